"""Estimate minus truth at the estimate's epochs: position and velocity errors in ENU, attitude errors.

Errors are estimate - truth. Position error: C_e^n (p_est - p_true) in the ENU frame at the true position (m).
Velocity error: v_est - v_true, both Earth-relative in ENU (m/s). Attitude: the Euler differences
[pitch, roll, heading] wrapped to [-pi, pi) (rad), and the small-angle misalignment phi (ENU, rad) with
C_est = exp([phi x]) C_true, i.e. the rotation vector of C_est C_true^T.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .. import earth, frames
from ..solution import Solution
from .. import quat
from .errors import RefereeInputError
from .truth import Truth, at_point, overlap, point_lever, truth_at

# error states a covariance may carry, by the name in ``Solution.state_names``: (series, component, sign).
# ENU names are the simkit convention; NED names are accepted for third-party filters (down = -up).
STATE_SERIES = {
    **{f"pos_{a}": ("pos_enu", i, 1.0) for i, a in enumerate("enu")},
    **{f"vel_{a}": ("vel_enu", i, 1.0) for i, a in enumerate("enu")},
    **{f"att_{a}": ("att_enu", i, 1.0) for i, a in enumerate("enu")},
    "pos_d": ("pos_enu", 2, -1.0), "vel_d": ("vel_enu", 2, -1.0), "att_d": ("att_enu", 2, -1.0),
    "pitch": ("euler", 0, 1.0), "roll": ("euler", 1, 1.0), "heading": ("euler", 2, 1.0),
    # simkit.estimators' error states (computed minus true): C~ = (I - [phi x]) C, so phi = -att; dv = vel
    **{f"phi_{a}": ("att_enu", i, -1.0) for i, a in enumerate("enu")},
    **{f"dv_{a}": ("vel_enu", i, 1.0) for i, a in enumerate("enu")},
    "d_h": ("pos_enu", 2, 1.0),
    # latitude / longitude errors in radians: north / east metres over the radii of curvature (see Errors.state)
    "d_lat": ("pos_enu", 1, 1.0), "d_lon": ("pos_enu", 0, 1.0),
}


@dataclass(frozen=True)
class Errors:
    """K scored epochs ``t`` (s since start); ``pos_enu`` (K, 3) m, ``vel_enu`` (K, 3) m/s, ``euler`` (K, 3) rad
    [pitch, roll, heading], ``att_enu`` (K, 3) rad; None when the estimate lacks that part, NaN rows (or a NaN
    column: the roll of a single baseline) where it has no value. ``index`` (K,) are the rows of the estimate that
    were scored (those inside the truth span, with finite epochs). ``lla`` (K, 3) and ``quat_nb`` (K, 4) are the
    truth at the solution's point."""

    t: np.ndarray
    index: np.ndarray
    pos_enu: np.ndarray | None
    vel_enu: np.ndarray | None
    euler: np.ndarray | None
    att_enu: np.ndarray | None
    lla: np.ndarray | None = None   # (K, 3) true lat, lon (rad), height (m): scales of d_lat / d_lon
    quat_nb: np.ndarray | None = None

    def factor(self, name: str):
        """(series, component, f) with the covariance state ``name`` = f * series[:, component] (f a number
        or (K,) array: 1/(R + h) terms for d_lat / d_lon), or None for a name outside :data:`STATE_SERIES`."""
        if name not in STATE_SERIES:
            return None
        series, k, sign = STATE_SERIES[name]
        if name in ("d_lat", "d_lon"):
            rm, rn = earth.radii(self.lla[:, 0])
            h = self.lla[:, 2]
            return series, k, 1.0 / ((rm + h) if name == "d_lat" else (rn + h) * np.cos(self.lla[:, 0]))
        return series, k, sign

    def state(self, name: str) -> np.ndarray | None:
        """The (K,) error series of a covariance state name (see :data:`STATE_SERIES`), or None."""
        found = self.factor(name)
        x = None if found is None else getattr(self, found[0])
        return None if x is None else found[2] * x[:, found[1]]


def _estimate_quat(sol: Solution, index: np.ndarray):
    """(quat (K, 4) body->ENU, euler (K, 3) rad) of the estimate's rows ``index``: NaN where it has no full
    attitude; the Euler angles as given (a NaN roll stays NaN); (None, None) without attitude."""
    if sol.quat_nb is not None:
        q = np.asarray(sol.quat_nb, dtype=float)[index]
        ok = np.all(np.isfinite(q), axis=1) & np.any(q != 0, axis=1)
        if ok.all():
            return q, frames.euler_from_attitude(Rotation.from_quat(q))
        eul = np.full((len(index), 3), np.nan)
        if ok.any():
            eul[ok] = frames.euler_from_attitude(Rotation.from_quat(q[ok]))
        return np.where(ok[:, None], q, np.nan), eul
    if sol.euler is None:
        return None, None
    eul = np.asarray(sol.euler, dtype=float)[index]
    return frames.quat_from_euler(*eul.T), eul      # NaN angles give NaN quaternions


def compare(truth: Truth, sol: Solution, where: str = "estimate") -> Errors:
    """Errors of ``sol`` against ``truth`` at the estimate epochs inside the truth span, at the solution's point
    (:func:`simkit.referee.truth.at_point`)."""
    if sol.pos_ecef is None and sol.vel_enu is None and sol.quat_nb is None and sol.euler is None:
        raise RefereeInputError(where, "the estimate has no position, velocity or attitude to score")
    lever = point_lever(truth, sol.point, where) if sol.pos_ecef is not None or sol.vel_enu is not None else None
    index = np.flatnonzero(overlap(truth, sol.t, where))
    t = np.asarray(sol.t, dtype=float)[index]
    if np.any(np.diff(t) <= 0):
        raise RefereeInputError(where, "estimate epochs must increase strictly")
    ref = at_point(truth_at(truth, t), lever, where)
    lla = frames.ecef_to_lla(ref.pos_ecef)
    pos = vel = eul = att = None
    if sol.pos_ecef is not None:
        pos = frames.ecef_to_enu_vec(np.asarray(sol.pos_ecef)[index] - ref.pos_ecef, lla[:, 0], lla[:, 1])
    if sol.vel_enu is not None:
        vel = np.asarray(sol.vel_enu)[index] - ref.vel_enu
    q, eul_est = _estimate_quat(sol, index)
    if q is not None:
        eul = frames.wrap(eul_est - frames.euler_from_attitude(Rotation.from_quat(ref.quat_nb)))
        att = quat.as_rotvec(quat.mul(q, quat.conj(ref.quat_nb)))
    return Errors(t, index, pos, vel, eul, att, lla, ref.quat_nb)
