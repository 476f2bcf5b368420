"""Per-epoch double-differenced float solution of r baselines (antenna k against antenna 0), arrays in and out.

Model for baseline k, signal g, satellite s with reference satellite ref(s) of its system (Wang 2018 eq 16 with
the baseline in ENU): lambda_g DD(phi) = -(e_s - e_ref) . b_k + lambda_g a_k,s + noise (m), DD(code) = -(e_s -
e_ref) . b_k + noise (m), e the unit line of sight receiver -> satellite in ENU. The float baseline comes from the
code (the carrier carries a free ambiguity per row), the float ambiguities from the carrier minus it:

    b_hat = (G' Wp G)^-1 G' Wp y_p,  a_hat = L^-1 (y_phi - G b_hat),
    Qb = (G' Wp G)^-1,  Qa = L^-1 (Qphi + G Qb G') L^-1,  Qba = -Qb G' L^-1,

with G = I_r (x) G_1 (baseline-major rows) and Qphi, Qp = D diag(sigma^2) D' from the undifferenced variances
(so the rows of different baselines that share antenna 0 are correlated, as they are). Epochs are grouped by
their channel pattern (which satellites / references / signals); every group is solved in one batch.

Several epochs (``epochs`` = N > 1): the ambiguities are constant over a window of the last N epochs of a run (a
run: consecutive epochs of one channel pattern without a loss-of-lock flag on any antenna for a satellite or
reference used; the window is shorter at the start of a run), the noise white in time. Kinematic (baseline per
epoch): the window's ambiguities are the information-weighted mean of the single-epoch floats,
Qa_w = (sum_k Qa_k^-1)^-1, a_w = Qa_w sum_k Qa_k^-1 a_k, and epoch j's baseline is conditioned on them,
b_j = b_hat_j + Qba_j Qa_j^-1 (a_w - a_j), Qba_w = Qba_j Qa_j^-1 Qa_w,
Qb_w = Qb_j - Qba_j Qa_j^-1 (Qa_j - Qa_w) Qa_j^-1 Qab_j (a Kalman update of epoch j's (b, a) by the other
epochs' independent ambiguity information). Static (one baseline over the window): the joint (b, a) of every
epoch combined the same way with its full covariance. Time-correlated errors (multipath) make both optimistic.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..gnss.differencing import dd_float, dd_matrix, symmetric, systems_of
from .errors import AttitudeInputError


@dataclass(frozen=True)
class Observations:
    """What the float solution reads, G signals, M epochs, A antennas, S satellites (NaN where not tracked).

    ``carrier`` (G, M, A, S) cycles; ``code`` (G, M, A, S) m; ``var_carrier`` / ``var_code`` (G, M, A, S) m^2
    undifferenced variances; ``wavelength`` (G,) m; ``los`` (M, S, 3) unit lines of sight receiver -> satellite
    in ENU; ``elevation`` (M, S) rad; ``sat_ids`` (S,) str (the system is the first letter);
    ``var_carrier_correlated`` (G, M, A, S) m^2 the part of ``var_carrier`` that is correlated in time
    (multipath), or None.
    """

    carrier: np.ndarray
    code: np.ndarray
    var_carrier: np.ndarray
    var_code: np.ndarray
    wavelength: np.ndarray
    los: np.ndarray
    elevation: np.ndarray
    sat_ids: np.ndarray
    var_carrier_correlated: np.ndarray | None = None

    def __post_init__(self):
        shape = np.shape(self.carrier)
        if len(shape) != 4:
            raise AttitudeInputError("carrier", f"shape {shape}; expected (G, M, A, S)")
        for name in ("code", "var_carrier", "var_code", "var_carrier_correlated"):
            if getattr(self, name) is not None and np.shape(getattr(self, name)) != shape:
                raise AttitudeInputError(name, f"shape {np.shape(getattr(self, name))}; expected {shape}")
        g, m, a, s = shape
        if a < 2:
            raise AttitudeInputError("carrier", f"{a} antenna(s); expected at least 2 (one baseline)")
        for name, want in (("wavelength", (g,)), ("los", (m, s, 3)), ("elevation", (m, s)), ("sat_ids", (s,))):
            if np.shape(getattr(self, name)) != want:
                raise AttitudeInputError(name, f"shape {np.shape(getattr(self, name))}; expected {want}")


@dataclass(frozen=True)
class FloatGroup:
    """The float solutions of K epochs sharing one channel pattern; n channels per baseline, r baselines.

    ``epochs`` (K,) indices into the M epochs; ``signal``, ``sat``, ``ref`` (n,) of each channel; ``a_hat`` (K, r n)
    cycles (baseline-major); ``Qa`` (K, r n, r n) cycles^2; ``b_hat`` (K, 3 r) m ENU; ``Qb`` (K, 3 r, 3 r) m^2;
    ``Qba`` (K, 3 r, r n) m cycles; ``G`` (K, n, 3) DD geometry (m per m of baseline); ``Qphi`` (K, r n, r n)
    DD carrier covariance m^2; ``Qphi_correlated`` (K, r n, r n) its time-correlated part (from
    ``Observations.var_carrier_correlated``, when asked for: ``float_solution(..., correlated=True)``), or None.
    """

    epochs: np.ndarray
    signal: np.ndarray
    sat: np.ndarray
    ref: np.ndarray
    a_hat: np.ndarray
    Qa: np.ndarray
    b_hat: np.ndarray
    Qb: np.ndarray
    Qba: np.ndarray
    G: np.ndarray
    Qphi: np.ndarray
    Qphi_correlated: np.ndarray | None = None


def channel_masks(obs: Observations, mask_rad: float = 0.0, max_sats: int | None = None) -> np.ndarray:
    """Usable (G, M, S): carrier and code on every antenna, elevation >= ``mask_rad``, and, with ``max_sats``,
    only the ``max_sats`` highest satellites of each epoch (counted over all systems, references included)."""
    ok = np.isfinite(obs.carrier).all(2) & np.isfinite(obs.code).all(2)
    ok &= (np.nan_to_num(obs.elevation, nan=-np.inf) >= mask_rad)[None]
    if max_sats is not None:
        el = np.where(ok.any(0), obs.elevation, -np.inf)
        rank = np.argsort(np.argsort(-el, axis=1), axis=1)
        ok &= (rank < max_sats)[None]
    return ok


def references(obs: Observations, usable: np.ndarray) -> np.ndarray:
    """Reference satellite (G, M, S) int of each signal, epoch and satellite's system (highest usable
    elevation), -1 where the system has fewer than 2 usable satellites."""
    sys = systems_of(obs.sat_ids)
    ref = np.full(usable.shape, -1, dtype=np.int64)
    for letter in np.unique(sys):
        cols = np.flatnonzero(sys == letter)
        el = np.where(usable[:, :, cols], obs.elevation[None, :, cols], -np.inf)
        best = cols[np.argmax(el, axis=2)]  # (G, M)
        enough = usable[:, :, cols].sum(2) >= 2
        ref[:, :, cols] = np.where(enough, best, -1)[..., None]
    return ref


def _patterns(usable, ref):
    """Epoch groups (list of (epochs, signal, sat, ref)) with the same channels and references."""
    g, m, s = usable.shape
    chan = usable & (ref >= 0) & (ref != np.arange(s))
    key = np.concatenate([chan.transpose(1, 0, 2).reshape(m, -1), ref.transpose(1, 0, 2).reshape(m, -1)], 1)
    uniq, inverse = np.unique(key, axis=0, return_inverse=True)
    groups = []
    for u in range(len(uniq)):
        epochs = np.flatnonzero(inverse.reshape(-1) == u)
        sig, sat = np.nonzero(chan[:, epochs[0], :])
        if len(sat) >= 3:
            groups.append((epochs, sig, sat, ref[sig, epochs[0], sat]))
    return groups


def float_solution(obs: Observations, mask_rad: float = 0.0, max_sats: int | None = None, epochs: int = 1,
                   static: bool = False, lli: np.ndarray | None = None, correlated: bool = False) -> list[FloatGroup]:
    """Float DD solutions of every epoch with at least 3 DD channels, grouped by channel pattern; with
    ``epochs`` > 1 each over the window of the last ``epochs`` epochs (module docstring), ``static`` with one
    baseline over the window, windows reset at a gap and at a loss-of-lock flag of ``lli`` (G, M, A, S);
    ``correlated``: also the time-correlated part of the DD carrier covariance (``Qphi_correlated``)."""
    if int(epochs) < 1:
        raise AttitudeInputError("epochs", f"{epochs}; expected an integer >= 1")
    usable = channel_masks(obs, mask_rad, max_sats)
    ref = references(obs, usable)
    groups = [_solve_group(obs, *grp, correlated=correlated) for grp in _patterns(usable, ref)]
    if int(epochs) == 1:
        return groups
    return [multi_epoch(grp, run_breaks(grp, lli), int(epochs), static) for grp in groups]


def run_breaks(grp: FloatGroup, lli: np.ndarray | None) -> np.ndarray:
    """(K,) bool: where a run of the group's epochs starts: the first epoch, after a gap, or at a loss-of-lock
    flag (``lli`` (G, M, A, S) > 0; None: none) on any antenna for a satellite or reference used."""
    e = grp.epochs
    out = np.ones(len(e), bool)
    out[1:] = np.diff(e) != 1
    if lli is not None:
        flags = lli[grp.signal[:, None], e[None, :]][:, :, :, np.concatenate([grp.sat, grp.ref])] > 0
        out |= flags.any(axis=(0, 2, 3))
    return out


def _window_sum(x: np.ndarray, start: np.ndarray, n: int) -> np.ndarray:
    """sum of x[j - l] for l = 0 .. n-1 with j - l >= start[j] (the run's first index), along axis 0."""
    out = x.copy()
    idx = np.arange(len(x))
    for lag in range(1, min(n, len(x))):
        ok = idx - lag >= start
        out[ok] += x[idx[ok] - lag]
    return out


def _window_mean(x: np.ndarray, info: np.ndarray, start: np.ndarray, n: int):
    """Information-weighted mean (K, d) and its covariance (K, d, d) of the estimates ``x`` (K, d) with
    information matrices ``info`` (K, d, d) over each epoch's window of the last ``n`` epochs of its run."""
    P_w = symmetric(np.linalg.inv(_window_sum(info, start, n)))
    return np.einsum("kij,kj->ki", P_w, _window_sum(np.einsum("kij,kj->ki", info, x), start, n)), P_w


def multi_epoch(grp: FloatGroup, breaks: np.ndarray, n: int, static: bool = False) -> FloatGroup:
    """The group's floats over windows of the last ``n`` epochs of each run (``breaks`` (K,) run starts)."""
    start = np.maximum.accumulate(np.where(breaks, np.arange(len(breaks)), 0))
    if static:
        x = np.concatenate([grp.b_hat, grp.a_hat], 1)
        P = np.block([[grp.Qb, grp.Qba], [np.swapaxes(grp.Qba, 1, 2), grp.Qa]])
        x_w, P_w = _window_mean(x, np.linalg.inv(P), start, n)
        nb = grp.b_hat.shape[1]
        return FloatGroup(grp.epochs, grp.signal, grp.sat, grp.ref, x_w[:, nb:], P_w[:, nb:, nb:], x_w[:, :nb],
                          P_w[:, :nb, :nb], P_w[:, :nb, nb:], grp.G, grp.Qphi, grp.Qphi_correlated)
    info = np.linalg.inv(grp.Qa)
    a_w, Qa_w = _window_mean(grp.a_hat, info, start, n)
    T = grp.Qba @ info  # Qba Qa^-1
    b_w = grp.b_hat + np.einsum("kij,kj->ki", T, a_w - grp.a_hat)
    Qb_w = grp.Qb - T @ (grp.Qa - Qa_w) @ np.swapaxes(T, 1, 2)
    return FloatGroup(grp.epochs, grp.signal, grp.sat, grp.ref, a_w, Qa_w, b_w, symmetric(Qb_w), T @ Qa_w, grp.G,
                      grp.Qphi, grp.Qphi_correlated)


def _solve_group(obs: Observations, epochs, signal, sat, ref, correlated: bool = False) -> FloatGroup:
    """Batch least squares of one channel pattern (see the module docstring)."""
    n_ant = obs.carrier.shape[2]
    r, n = n_ant - 1, len(sat)
    sigs, sig_i = np.unique(signal, return_inverse=True)
    cols, col_i = np.unique(np.concatenate([sat, ref]), return_inverse=True)  # only the satellites used
    D = dd_matrix(sig_i, col_i[:n], col_i[n:], n_ant, len(cols), len(sigs))
    lam = np.tile(obs.wavelength[signal], r)  # (r n,)

    def take(x):  # (G, M, A, S) -> (K, G' A S') in the column order of D
        sub = x[sigs[:, None], epochs[None, :]][..., cols]
        return np.nan_to_num(sub.transpose(1, 0, 2, 3).reshape(len(epochs), -1))

    y_phi = (take(obs.carrier) * np.repeat(obs.wavelength[sigs], n_ant * len(cols))) @ D.T
    y_p = take(obs.code) @ D.T
    Qphi = np.einsum("ij,kj,lj->kil", D, take(obs.var_carrier), D, optimize=True)
    Qp = np.einsum("ij,kj,lj->kil", D, take(obs.var_code), D, optimize=True)
    Qc = None
    if correlated and obs.var_carrier_correlated is not None:
        Qc = np.einsum("ij,kj,lj->kil", D, take(obs.var_carrier_correlated), D, optimize=True)
    e = obs.los[epochs]
    G1 = -(e[:, sat, :] - e[:, ref, :])  # (K, n, 3)
    G = np.zeros((len(epochs), r * n, 3 * r))
    for k in range(r):
        G[:, k * n:(k + 1) * n, 3 * k:3 * k + 3] = G1
    f = dd_float(G, y_phi, y_p, Qphi, Qp, lam)
    return FloatGroup(epochs, signal, sat, ref, f.a_hat, f.Qa, f.b_hat, f.Qb, f.Qba, G1, Qphi, Qc)
