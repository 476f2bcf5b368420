"""Error statistics, convergence times and chi-square consistency tests (NEES, NIS).

Quantities (name -> unit): position ``east``, ``north``, ``up``, ``horizontal``, ``position_3d`` (m); velocity
``vel_east``, ``vel_north``, ``vel_up``, ``vel_horizontal``, ``velocity_3d`` (m/s); attitude ``pitch``,
``roll``, ``heading`` (Euler differences) and ``attitude_3d`` (misalignment angle |phi|), in degrees.
Statistics of each: ``rms``, ``mean``, ``std``, ``max`` (of |e|), ``p50``, ``p95``, ``p99`` (percentiles of |e|).

NEES (normalised estimation error squared) e_k^T P_k^-1 e_k over the covariance states the referee recognises
is chi-square with n degrees of freedom for a consistent filter: the two-sided bounds at confidence c are
chi2.ppf((1 -+ c) / 2, n) per epoch, and chi2.ppf((1 -+ c) / 2, K n) / K for the mean over K epochs
(Bar-Shalom, Li & Kirubarajan 2001, sec. 5.4). NIS is tested the same way from a filter's own ``nis`` and
``nis_dof`` extras.

At each epoch the NEES uses the recognised states that have a finite error and a finite variance there, so n is
per epoch: a state a solution does not estimate at an epoch (a NaN block of its covariance, or a NaN error) leaves
the test and reduces its dimension. A NaN covariance between two states that both have finite variances is taken
as no correlation: the solution estimated them as separate blocks (SPP's position and velocity); the NEES is then
the sum of the blocks' NEES.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation
from scipy.stats import chi2

from .. import frames
from .compare import STATE_SERIES, Errors

STATS = ("rms", "mean", "std", "max", "p50", "p95", "p99")
UNITS = {"m": ("east", "north", "up", "horizontal", "position_3d"),
         "m_per_s": ("vel_east", "vel_north", "vel_up", "vel_horizontal", "velocity_3d"),
         "deg": ("pitch", "roll", "heading", "attitude_3d")}
UNIT_OF = {q: u for u, names in UNITS.items() for q in names}


def series(err: Errors) -> dict[str, np.ndarray]:
    """Every scored quantity's (K,) error series, in the units of :data:`UNIT_OF` (attitude in degrees)."""
    out = {}
    for vec, names in ((err.pos_enu, UNITS["m"]), (err.vel_enu, UNITS["m_per_s"])):
        if vec is not None:
            out.update(zip(names[:3], vec.T))
            out[names[3]] = np.hypot(vec[:, 0], vec[:, 1])
            out[names[4]] = np.linalg.norm(vec, axis=1)
    if err.euler is not None:
        out.update(zip(UNITS["deg"][:3], np.degrees(err.euler).T))
        out["attitude_3d"] = np.degrees(np.linalg.norm(err.att_enu, axis=1))
    return out


def not_estimated(err: Errors, series_: dict) -> list[str]:
    """What the estimate does not give, in words and quantity names: "position", "velocity", "attitude" for a
    missing part, and each quantity whose error series has no finite value (the roll of a single baseline)."""
    parts = [name for name, x in (("position", err.pos_enu), ("velocity", err.vel_enu), ("attitude", err.euler))
             if x is None]
    return parts + [q for q, x in series_.items() if not np.isfinite(x).any()]


def statistics(x: np.ndarray) -> dict[str, float]:
    """RMS, mean, std, max |x| and the 50/95/99 % percentiles of |x| over the finite samples of ``x``."""
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return {k: float("nan") for k in STATS}
    a = np.abs(x)
    p50, p95, p99 = np.percentile(a, [50, 95, 99])
    return {"rms": float(np.sqrt(np.mean(x * x))), "mean": float(x.mean()), "std": float(x.std()),
            "max": float(a.max()), "p50": float(p50), "p95": float(p95), "p99": float(p99)}


def convergence_time(t: np.ndarray, x: np.ndarray, threshold: float) -> float | None:
    """Seconds from the first scored epoch until |x| stays at or below ``threshold`` for good (0 when it never
    exceeds it, None when it still exceeds it at the last finite epoch). Epochs without an estimate (NaN) neither
    exceed nor meet the threshold: a gap in the fixes is not a divergence."""
    finite = np.flatnonzero(np.isfinite(x))
    above = finite[np.abs(x[finite]) > threshold]
    if above.size == 0:
        return 0.0
    later = finite[finite > above[-1]]
    return None if later.size == 0 else float(t[later[0]] - t[0])


def nees(err: Errors, cov: np.ndarray, state_names, confidence: float = 0.95) -> dict | None:
    """NEES of the covariance states recognised in ``state_names`` (see ``STATE_SERIES``); None when none is.
    ``cov`` (K_all, X, X) in SI units is indexed by ``err.index``."""
    used = [(j, name) for j, name in enumerate(state_names) if err.state(name) is not None]
    if not used:
        return None
    cols = [j for j, _ in used]
    e = np.stack([err.state(name) for _, name in used], axis=-1)
    P = np.asarray(cov, dtype=float)[np.ix_(err.index, cols, cols)]
    value, dof = reduced_nees(e, P)
    out = chi_square(value, dof, confidence)
    out.update(states=[name for _, name in used], series=value, dof=dof)
    return out


def reduced_nees(e: np.ndarray, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """NEES (K,) and its dimension (K,) from errors ``e`` (K, n) and covariances ``P`` (K, n, n) over the states
    with a finite error and variance at each epoch (NaN cross-covariances among them taken as 0, see the module
    docstring); NaN and dimension 0 at an epoch without any such state."""
    n = e.shape[1]
    avail = np.isfinite(e) & np.isfinite(np.einsum("kii->ki", P))
    dof = avail.sum(axis=1)
    if avail.all() and np.isfinite(P).all():     # the common case: nothing to leave out
        Pr, er = P, e
    else:   # states left out get an identity row/column and a zero error: they add nothing to e^T P^-1 e
        Pr = np.where(avail[:, :, None] & avail[:, None, :], P, np.eye(n))
        Pr[np.isnan(Pr)] = 0.0                   # what NaN is left is a cross-covariance between kept states
        er = np.where(avail, e, 0.0)
    value = np.full(len(e), np.nan)
    ok = dof > 0
    if ok.any():
        value[ok] = np.einsum("ki,ki->k", er[ok], np.linalg.solve(Pr[ok], er[ok][..., None])[..., 0])
    return value, dof


def sigma_bands(err: Errors, cov: np.ndarray, state_names) -> dict[str, np.ndarray]:
    """Standard deviations (K, 3) of the ``pos_enu`` (m), ``vel_enu`` (m/s) and ``euler`` (rad) error series
    that the covariance ``cov`` (K_all, X, X) implies at the scored epochs (NaN for a component it does not
    cover): a state mapped onto one component by :meth:`Errors.factor` (pos_n, d_lat, vel_d, heading, ...)
    gives sqrt(P_jj) / |f|; without Euler states, a full misalignment (att_* or phi_*) gives the Euler sigmas
    through the first-order map d euler = G d att (G from the true attitude)."""
    P = np.asarray(cov, dtype=float)[err.index]
    var = np.einsum("kii->ki", P)
    out = {s: np.full((len(err.t), 3), np.nan) for s in ("pos_enu", "vel_enu", "euler", "att_enu")}
    att_cols = [None, None, None]
    for j, name in enumerate(state_names):
        found = err.factor(name)
        if found is None:
            continue
        series_name, k, f = found
        if np.all(np.isnan(out[series_name][:, k])):
            out[series_name][:, k] = np.sqrt(var[:, j]) / np.abs(f)
            if series_name == "att_enu":
                att_cols[k] = (j, f)
    if np.all(np.isnan(out["euler"])) and None not in att_cols and err.quat_nb is not None:
        idx = [j for j, _ in att_cols]
        S = np.diag([1.0 / f for _, f in att_cols])          # att = S state (f = +-1)
        P_att = S @ P[:, idx][:, :, idx] @ S
        G = frames.euler_jacobian(Rotation.from_quat(err.quat_nb))
        out["euler"] = np.sqrt(np.einsum("kij,kjl,kil->ki", G, P_att, G))
    del out["att_enu"]
    return out


def chi_square(value: np.ndarray, dof: np.ndarray, confidence: float = 0.95) -> dict:
    """Per-epoch and mean chi-square tests of ``value`` (K,) with ``dof`` (K,) degrees of freedom (NaN epochs
    are left out): fraction of epochs inside the two-sided bounds, mean and its bounds."""
    ok = np.isfinite(value) & np.isfinite(dof) & (dof > 0)
    v, d = value[ok], dof[ok]
    lo_q, hi_q = (1 - confidence) / 2, (1 + confidence) / 2
    dofs, which = np.unique(d, return_inverse=True)          # a few distinct dof: one ppf each
    inside = (v >= chi2.ppf(lo_q, dofs)[which]) & (v <= chi2.ppf(hi_q, dofs)[which])
    k = int(ok.sum())
    return {"epochs": k, "dof_mean": float(d.mean()) if k else float("nan"), "confidence": confidence,
            "fraction_inside": float(inside.mean()) if k else float("nan"),
            "mean": float(v.mean()) if k else float("nan"),
            "mean_bounds": list(mean_bounds(float(d.sum()), k, confidence)) if k else None,
            "epoch_bounds": [float(chi2.ppf(lo_q, d.mean())), float(chi2.ppf(hi_q, d.mean()))] if k else None}


def mean_bounds(total_dof: float, count: int, confidence: float = 0.95) -> tuple[float, float]:
    """Two-sided bounds at ``confidence`` of the mean of ``count`` independent chi-square values whose degrees of
    freedom add up to ``total_dof`` (the mean over K epochs, or over N runs of one epoch: total_dof = N n):
    chi2.ppf((1 -+ c) / 2, total_dof) / count."""
    lo_q, hi_q = (1 - confidence) / 2, (1 + confidence) / 2
    return float(chi2.ppf(lo_q, total_dof) / count), float(chi2.ppf(hi_q, total_dof) / count)


def nis(err: Errors, extras: dict, confidence: float = 0.95) -> dict | None:
    """NIS test from the solution extras ``nis`` (K,) and ``nis_dof`` (K,) (NaN or 0 dof where no update)."""
    if "nis" not in extras or "nis_dof" not in extras:
        return None
    value = np.asarray(extras["nis"], dtype=float)[err.index]
    out = chi_square(value, np.asarray(extras["nis_dof"], dtype=float)[err.index], confidence)
    out["series"] = value
    return out


__all__ = ["STATE_SERIES", "STATS", "UNITS", "UNIT_OF", "chi_square", "convergence_time", "mean_bounds", "nees", "nis",
           "not_estimated", "reduced_nees", "series", "sigma_bands", "statistics"]
