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
from . import quat
from .errors import RefereeInputError
from .truth import Truth, overlap, truth_at

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
    [pitch, roll, heading], ``att_enu`` (K, 3) rad; None when the estimate lacks that part. ``index`` (K,) are
    the rows of the estimate that were scored (those inside the truth span, with finite epochs)."""

    t: np.ndarray
    index: np.ndarray
    pos_enu: np.ndarray | None
    vel_enu: np.ndarray | None
    euler: np.ndarray | None
    att_enu: np.ndarray | None
    lla: np.ndarray | None = None   # (K, 3) true lat, lon (rad), height (m): scales of d_lat / d_lon

    def state(self, name: str) -> np.ndarray | None:
        """The (K,) error series of a covariance state name (see :data:`STATE_SERIES`), or None."""
        if name not in STATE_SERIES:
            return None
        series, k, sign = STATE_SERIES[name]
        x = getattr(self, series)
        if x is None:
            return None
        if name in ("d_lat", "d_lon"):
            rm, rn = earth.radii(self.lla[:, 0])
            h = self.lla[:, 2]
            return x[:, k] / ((rm + h) if name == "d_lat" else (rn + h) * np.cos(self.lla[:, 0]))
        return sign * x[:, k]


def wrap(angle):
    """Angles (rad) wrapped to [-pi, pi)."""
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi


def estimate_rotation(sol: Solution) -> Rotation | None:
    """Body->ENU attitude of a solution, from its quaternions or else its Euler angles."""
    if sol.quat_nb is not None:
        return Rotation.from_quat(sol.quat_nb)
    if sol.euler is not None:
        return frames.attitude_from_euler(sol.euler[:, 0], sol.euler[:, 1], sol.euler[:, 2])
    return None


def compare(truth: Truth, sol: Solution, where: str = "estimate") -> Errors:
    """Errors of ``sol`` against ``truth`` at the estimate epochs inside the truth span."""
    if sol.pos_ecef is None and sol.vel_enu is None and sol.quat_nb is None and sol.euler is None:
        raise RefereeInputError(where, "the estimate has no position, velocity or attitude to score")
    index = np.flatnonzero(overlap(truth, sol.t, where))
    t = np.asarray(sol.t, dtype=float)[index]
    if np.any(np.diff(t) <= 0):
        raise RefereeInputError(where, "estimate epochs must increase strictly")
    ref = truth_at(truth, t)
    pos = vel = eul = att = None
    if sol.pos_ecef is not None:
        lla = frames.ecef_to_lla(ref.pos_ecef)
        pos = frames.ecef_to_enu_vec(np.asarray(sol.pos_ecef)[index] - ref.pos_ecef, lla[:, 0], lla[:, 1])
    if sol.vel_enu is not None:
        vel = np.asarray(sol.vel_enu)[index] - ref.vel_enu
    rot = estimate_rotation(sol)
    if rot is not None:
        rot, rot_true = rot[index], Rotation.from_quat(ref.quat_nb)
        eul = wrap(frames.euler_from_attitude(rot) - frames.euler_from_attitude(rot_true))
        att = quat.as_rotvec(quat.mul(rot.as_quat(), quat.conj(ref.quat_nb)))
    return Errors(t, index, pos, vel, eul, att, frames.ecef_to_lla(ref.pos_ecef))
