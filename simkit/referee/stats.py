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
"""
from __future__ import annotations

import numpy as np
from scipy.stats import chi2

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
    exceeds it, None when it still exceeds it at the last epoch)."""
    above = np.flatnonzero(~(np.abs(x) <= threshold))
    if above.size == 0:
        return 0.0
    last = above[-1]
    return None if last == len(t) - 1 else float(t[last + 1] - t[0])


def nees(err: Errors, cov: np.ndarray, state_names, confidence: float = 0.95) -> dict | None:
    """NEES of the covariance states recognised in ``state_names`` (see ``STATE_SERIES``); None when none is.
    ``cov`` (K_all, X, X) in SI units is indexed by ``err.index``."""
    used = [(j, name) for j, name in enumerate(state_names) if err.state(name) is not None]
    if not used:
        return None
    cols = [j for j, _ in used]
    e = np.stack([err.state(name) for _, name in used], axis=-1)
    P = np.asarray(cov, dtype=float)[np.ix_(err.index, cols, cols)]
    ok = np.all(np.isfinite(e), axis=1) & np.all(np.isfinite(P), axis=(1, 2))
    value = np.full(len(e), np.nan)
    if ok.any():
        value[ok] = np.einsum("ki,ki->k", e[ok], np.linalg.solve(P[ok], e[ok][..., None])[..., 0])
    out = chi_square(value, np.full(len(e), len(used)), confidence)
    out.update(states=[name for _, name in used], series=value)
    return out


def chi_square(value: np.ndarray, dof: np.ndarray, confidence: float = 0.95) -> dict:
    """Per-epoch and mean chi-square tests of ``value`` (K,) with ``dof`` (K,) degrees of freedom (NaN epochs
    are left out): fraction of epochs inside the two-sided bounds, mean and its bounds."""
    ok = np.isfinite(value) & np.isfinite(dof) & (dof > 0)
    v, d = value[ok], dof[ok]
    lo_q, hi_q = (1 - confidence) / 2, (1 + confidence) / 2
    dofs, which = np.unique(d, return_inverse=True)          # a few distinct dof: one ppf each
    inside = (v >= chi2.ppf(lo_q, dofs)[which]) & (v <= chi2.ppf(hi_q, dofs)[which])
    k, total = int(ok.sum()), float(d.sum())
    return {"epochs": k, "dof_mean": float(d.mean()) if k else float("nan"), "confidence": confidence,
            "fraction_inside": float(inside.mean()) if k else float("nan"),
            "mean": float(v.mean()) if k else float("nan"),
            "mean_bounds": [float(chi2.ppf(lo_q, total) / k), float(chi2.ppf(hi_q, total) / k)] if k else None,
            "epoch_bounds": [float(chi2.ppf(lo_q, d.mean())), float(chi2.ppf(hi_q, d.mean()))] if k else None}


def nis(err: Errors, extras: dict, confidence: float = 0.95) -> dict | None:
    """NIS test from the solution extras ``nis`` (K,) and ``nis_dof`` (K,) (NaN or 0 dof where no update)."""
    if "nis" not in extras or "nis_dof" not in extras:
        return None
    value = np.asarray(extras["nis"], dtype=float)[err.index]
    out = chi_square(value, np.asarray(extras["nis_dof"], dtype=float)[err.index], confidence)
    out["series"] = value
    return out


__all__ = ["STATE_SERIES", "STATS", "UNITS", "UNIT_OF", "chi_square", "convergence_time", "nees", "nis",
           "series", "statistics"]
