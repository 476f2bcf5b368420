"""The reference trajectory of a simkit file, and its value at any epoch inside its span.

Position is interpolated in ECEF with cubic Hermite polynomials that use the truth velocity (rotated from ENU to
ECEF at each sample), so the interpolation error is O(jerk dt^4): below 1 um at 100 Hz for 10 g manoeuvres;
velocity is interpolated linearly (O(jerk dt^2 / 8), < 0.2 mm/s at 100 Hz and 10 m/s^3) and attitude by
spherical linear interpolation of the body->ENU quaternions.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import frames
from ..io import open_dataset
from . import quat
from .errors import RefereeInputError


@dataclass(frozen=True)
class Truth:
    """N truth samples: ``t`` (N,) s since start; ``pos_ecef`` (N, 3) m; ``vel_enu`` (N, 3) m/s (Earth-relative,
    ENU at the position); ``quat_nb`` (N, 4) body->ENU scalar-last."""

    t: np.ndarray
    pos_ecef: np.ndarray
    vel_enu: np.ndarray
    quat_nb: np.ndarray


def read_truth(path, t_min: float | None = None, t_max: float | None = None) -> Truth:
    """``/truth/t``, ``pos_ecef``, ``vel_enu`` and ``quat_nb`` of the simkit file ``path``; with ``t_min`` /
    ``t_max`` (s) only the samples that bracket that span are read (bounded memory for long files)."""
    with open_dataset(path) as ds:
        missing = [k for k in ("t", "pos_ecef", "vel_enu", "quat_nb") if f"truth/{k}" not in ds]
        if missing:
            raise RefereeInputError(path, f"no /truth/{missing[0]} dataset: scoring needs the truth trajectory")
        t = ds["truth/t"][:]
        lo = 0 if t_min is None else max(int(np.searchsorted(t, t_min, side="right")) - 1, 0)
        hi = len(t) if t_max is None else min(int(np.searchsorted(t, t_max, side="left")) + 1, len(t))
        if hi - lo < 2:   # the span misses the truth: keep two samples so that overlap() names the spans
            lo, hi = 0, len(t)
        return Truth(t[lo:hi], *(ds[f"truth/{k}"][lo:hi] for k in ("pos_ecef", "vel_enu", "quat_nb")))


def overlap(truth: Truth, t: np.ndarray, where: str = "estimate") -> np.ndarray:
    """Boolean mask of the epochs ``t`` inside the truth span; a clear error when there is none."""
    t = np.asarray(t, dtype=float)
    inside = (t >= truth.t[0]) & (t <= truth.t[-1]) & np.isfinite(t)
    if not inside.any():
        span = f"{t.min():.3f} .. {t.max():.3f} s" if np.isfinite(t).any() and t.size else "no finite epoch"
        raise RefereeInputError(where, f"estimate epochs ({span}) do not overlap the truth span "
                                       f"({truth.t[0]:.3f} .. {truth.t[-1]:.3f} s since the scenario start)")
    return inside


def truth_at(truth: Truth, t: np.ndarray) -> Truth:
    """The truth at epochs ``t`` (K,) s, all inside the truth span (see :func:`overlap`)."""
    t = np.asarray(t, dtype=float)
    i = np.clip(np.searchsorted(truth.t, t, side="right") - 1, 0, len(truth.t) - 2)
    t0, t1 = truth.t[i], truth.t[i + 1]
    h = t1 - t0
    s = ((t - t0) / h)[:, None]
    # ENU -> ECEF velocity at both end points, each in its own sample's geodetic frame
    lat_lon = frames.ecef_to_lla(truth.pos_ecef[np.r_[i, i + 1]])[:, :2]
    v_ecef = frames.enu_to_ecef_vec(truth.vel_enu[np.r_[i, i + 1]], lat_lon[:, 0], lat_lon[:, 1])
    v0, v1 = v_ecef[: t.size], v_ecef[t.size:]
    p0, p1 = truth.pos_ecef[i], truth.pos_ecef[i + 1]
    h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
    pos = h00 * p0 + h10 * h[:, None] * v0 + h01 * p1 + h11 * h[:, None] * v1
    vel = (1 - s) * truth.vel_enu[i] + s * truth.vel_enu[i + 1]
    q0, q1 = truth.quat_nb[i], truth.quat_nb[i + 1]
    rel = quat.as_rotvec(quat.mul(quat.conj(q0), q1))          # slerp: q0 exp(s log(q0^-1 q1))
    return Truth(t, pos, vel, quat.mul(q0, quat.from_rotvec(rel * s)))
