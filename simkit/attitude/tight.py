"""Fixed double-differenced carrier as a measurement for a tightly coupled INS filter (``kf15_dd``, docs/estimators.md).

For each epoch whose ambiguities are fixed and validated (a full fix accepted by the ratio test, or held from
such a fix by continuity), every DD channel of every baseline k (antenna k against antenna 0) gives

    y = lambda (DD phi - N_fixed) = G_s . b_k^n + noise   (m),   G_s = -(e_s - e_ref)  (ENU, unitless),

the model of ``dd.py`` (Wang 2018 eq 16 with the baseline in ENU), so that with the body-frame baseline f_k
(lever arm of antenna k minus antenna 0) the INS predicts G_s . C_b^n f_k. A channel with a loss-of-lock flag
on antenna 0 or k, for its satellite or its reference, at that epoch is left out; so are float, partial and
unfinished epochs. The noise covariance is the DD carrier covariance D diag(sigma^2) D' of the float solution
(correlated across channels sharing the reference and across baselines sharing antenna 0).

Arrays in, arrays out: :func:`fixed_dd` takes a :class:`~simkit.attitude.reading.FileData`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .dd import FloatGroup, float_solution
from .errors import AttitudeInputError
from .resolve import METHODS, Resolution, resolve, resolve_held
from .solvers import body_baselines, continuity_breaks, resolve_options, _wrong
from .reading import FileData


@dataclass(frozen=True)
class FixedDD:
    """K epochs with at least one usable fixed DD row, T rows in all (row-major per epoch).

    ``t`` (K,) s; ``epoch`` (K,) index into the file's epochs; ``offsets`` (K + 1,) rows of epoch i are
    offsets[i]:offsets[i+1]; ``los_enu`` (T, 3) the DD geometry row G_s = -(e_s - e_ref) (ENU); ``baseline_b``
    (T, 3) m body baseline of the row; ``range_m`` (T,) m = lambda (DD phi - N); ``cov`` (sum m_i^2,) m^2
    the epochs' DD covariance blocks flattened row-major; ``wrong`` (K,) bool: the fix differs from the file's
    true ambiguities (a label for studies, not used to select); ``n_dropped_lli`` rows left out by LLI flags.
    """

    t: np.ndarray
    epoch: np.ndarray
    offsets: np.ndarray
    los_enu: np.ndarray
    baseline_b: np.ndarray
    range_m: np.ndarray
    cov: np.ndarray
    wrong: np.ndarray
    n_dropped_lli: int


def _dd_phase(fd: FileData, grp: FloatGroup) -> np.ndarray:
    """DD carrier (K, r n) in metres, baseline-major, and the LLI flags (K, r n) of its channels."""
    e, sig = grp.epochs, grp.signal
    car, lli = fd.obs.carrier, fd.lli
    cs = car[sig[None, :], e[:, None], :, grp.sat[None, :]]  # (K, n, A)
    cr = car[sig[None, :], e[:, None], :, grp.ref[None, :]]
    dd = (cs[..., 1:] - cs[..., :1]) - (cr[..., 1:] - cr[..., :1])  # (K, n, r)
    fl = (lli[sig[None, :], e[:, None], :, grp.sat[None, :]] > 0) | (lli[sig[None, :], e[:, None], :,
                                                                          grp.ref[None, :]] > 0)
    flag = fl[..., :1] | fl[..., 1:]  # antenna 0 or antenna k
    K, n, r = dd.shape
    lam = fd.obs.wavelength[sig][None, :, None]
    return (dd * lam).transpose(0, 2, 1).reshape(K, r * n), flag.transpose(0, 2, 1).reshape(K, r * n)


def correlation_inflation(correlation_s: float, interval_s: float, window: float = np.inf) -> float:
    """Variance factor of the time-correlated DD noise for a filter that takes it as white: a first-order
    Gauss-Markov error of correlation time ``correlation_s`` sampled every ``interval_s`` (rho = exp(-dt/tau))
    averaged over ``window`` samples has the variance of the mean sigma^2 f / n with
    f = 1 + 2 sum_{k=1}^{n-1} (1 - k/n) rho^k, -> (1 + rho) / (1 - rho) for a long window: the white-noise
    variance that gives the same information. 1 when ``correlation_s`` <= 0 (white)."""
    if not correlation_s > 0:
        return 1.0
    rho = np.exp(-interval_s / correlation_s)
    if not np.isfinite(window):
        return float((1 + rho) / (1 - rho))
    k = np.arange(1, max(int(window), 1))
    return float(1 + 2 * np.sum((1 - k / window) * rho ** k))


def group_rows(fd: FileData, grp: FloatGroup, res: Resolution, F: np.ndarray, inflation: float = 1.0) -> list:
    """[(epoch, G rows (m, 3), f rows (m, 3), y (m,), R (m, m), wrong)] of the group's usable epochs; R is the DD
    carrier covariance with its time-correlated part (``grp.Qphi_correlated``) times ``inflation``."""
    n, r = len(grp.sat), F.shape[1]
    phase, flag = _dd_phase(fd, grp)
    lam = np.tile(fd.obs.wavelength[grp.signal], r)
    y = phase - lam * res.z  # res.z NaN where nothing was accepted
    keep = res.accepted[:, None] & res.finished[:, None] & ~flag & np.isfinite(y)
    G = np.tile(grp.G, (1, r, 1))
    f = np.repeat(F.T, n, axis=0)
    wrong, _ = _wrong(grp, res, fd)
    Q = grp.Qphi if inflation == 1.0 else grp.Qphi + (inflation - 1.0) * grp.Qphi_correlated
    out = []
    for i in np.flatnonzero(keep.any(1)):
        k = keep[i]
        out.append((grp.epochs[i], G[i, k], f[k], y[i, k], Q[i][np.ix_(k, k)], wrong[i],
                    int((res.accepted[i] & flag[i]).sum())))
    return out


def fixed_dd(fd: FileData, method: str, p: dict, correlation_s: float = 0.0, window: float = np.inf) -> FixedDD:
    """The fixed DD carrier of every epoch of ``fd`` with ``method`` (lambda, clambda, mclambda) and the
    ambiguity parameters ``p`` (``simkit.attitude.params.AMBIGUITY_DEFAULTS``); with ``correlation_s`` > 0 the
    multipath part of the covariance is inflated by :func:`correlation_inflation` (epoch interval from ``fd.t``,
    ``window`` samples)."""
    if method not in METHODS:
        raise AttitudeInputError("method", f"{method!r}; expected one of {', '.join(METHODS)}")
    F = body_baselines(fd.lever_arm)
    policy = resolve_options(p, partial=False)
    rows = []
    interval = float(np.median(np.diff(fd.t))) if len(fd.t) > 1 else 1.0
    inflation = correlation_inflation(correlation_s, interval, window)
    for grp in float_solution(fd.obs, np.radians(p["mask_deg"]), p["max_sats"] or None, p["float_epochs"],
                              bool(p["static"]), fd.lli, correlated=inflation != 1.0):
        if p["continuity"] and p["every"] == 1:
            res = resolve_held(grp, method, F, continuity_breaks(grp, fd.lli), policy)
        else:
            res = resolve(grp, method, F, policy)
        rows += group_rows(fd, grp, res, F, inflation)
    rows.sort(key=lambda row: row[0])
    return _pack(fd, rows)


def _pack(fd: FileData, rows: list) -> FixedDD:
    m = np.array([len(row[3]) for row in rows], dtype=np.int64)
    cat = (lambda j, w: np.concatenate([row[j] for row in rows]) if rows else np.zeros((0,) + w))  # noqa: E731
    epoch = np.array([row[0] for row in rows], dtype=np.int64)
    cov = np.concatenate([row[4].ravel() for row in rows]) if rows else np.zeros(0)
    return FixedDD(fd.t[epoch], epoch, np.concatenate([[0], np.cumsum(m)]), cat(1, (3,)), cat(2, (3,)),
                   cat(3, ()), cov, np.array([row[5] for row in rows], bool), int(sum(row[6] for row in rows)))


def read_fixed_dd(ds, params: dict | None = None, method: str = "lambda", correlation_s: float = 0.0,
                  window: float = np.inf) -> FixedDD:
    """:func:`fixed_dd` of a simkit file (``simkit.io.Dataset``); ``params`` override the ambiguity defaults."""
    from .params import AMBIGUITY_DEFAULTS, merge
    from .reading import read
    p = merge(AMBIGUITY_DEFAULTS, params, "kf15_dd")
    return fixed_dd(read(ds, p), method, p, correlation_s, window)
