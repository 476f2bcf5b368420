"""What a trajectory produces: the :class:`TrajectoryTruth` block, and the body rate of simkit's Euler angles."""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from .. import frames


@dataclass(frozen=True)
class TrajectoryTruth:
    """A block of truth at the sample times ``t`` (s since start); one field per /truth dataset (README, "HDF5 layout")."""

    t: np.ndarray
    pos_ecef: np.ndarray
    pos_lla: np.ndarray
    vel_enu: np.ndarray
    quat_nb: np.ndarray
    euler: np.ndarray
    omega_ib_b: np.ndarray
    f_ib_b: np.ndarray

    def __len__(self):
        return len(self.t)

    def arrays(self) -> dict[str, np.ndarray]:
        """The fields by name (the arrays themselves, not copies)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def vel_ecef(self) -> np.ndarray:
        """Velocity relative to Earth in ECEF axes, (N, 3) m/s."""
        return frames.enu_to_ecef_vec(self.vel_enu, self.pos_lla[:, 0], self.pos_lla[:, 1])

    def take(self, index) -> "TrajectoryTruth":
        """The samples ``index`` (any numpy index along the time axis) of every field."""
        return TrajectoryTruth(**{k: v[index] for k, v in self.arrays().items()})


def body_rate_nb(pitch, roll, pitch_dot, roll_dot, heading_dot) -> np.ndarray:
    """w_nb^b (N, 3) rad/s of C_b^n = R_z(-heading) R_x(pitch) R_y(roll) from the Euler angles and their rates."""
    yaw_dot = -heading_dot
    cr, sr, cp = np.cos(roll), np.sin(roll), np.cos(pitch)
    return np.stack([cr * pitch_dot - sr * cp * yaw_dot,
                     np.sin(pitch) * yaw_dot + roll_dot,
                     sr * pitch_dot + cr * cp * yaw_dot], axis=-1)
