"""What a trajectory produces: the :class:`TrajectoryTruth` block, and the body rate of simkit's Euler angles."""
from __future__ import annotations

from dataclasses import dataclass, fields
from typing import NamedTuple

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


class Trig(NamedTuple):
    """sin and cos of an angle array x and of x / 2 (see :func:`trig`)."""

    sin: np.ndarray
    cos: np.ndarray
    half_sin: np.ndarray
    half_cos: np.ndarray


def sin_cos(x) -> tuple[np.ndarray, np.ndarray]:
    """sin and cos of ``x`` (rad) from t = tan(x / 2): 2 t / (1 + t^2) and (1 - t^2) / (1 + t^2).

    numpy evaluates float64 tan with SIMD kernels where the CPU has them (1.4 ns an element on AVX-512 against ~8
    ns for each of sin and cos, which have no such path), so the pair costs about an eighth: the sines and cosines
    were most of the truth's CPU. Within 3e-16 of numpy's sin and cos (a few units in the last place; tested), at
    any angle: t is finite for every float64 x (x / 2 is never exactly an odd multiple of pi / 2)."""
    t = np.tan(0.5 * np.asarray(x, dtype=float))
    t2 = t * t
    d = 1.0 / (1.0 + t2)
    return 2.0 * t * d, (1.0 - t2) * d


def trig(x) -> Trig:
    """sin and cos of ``x`` (rad) and of x / 2: the halves by :func:`sin_cos`, the full angles from them by the
    double-angle formulas (2 s c and (c - s)(c + s), within 8e-16): the quaternion needs the half angles."""
    s, c = sin_cos(0.5 * np.asarray(x, dtype=float))
    return Trig(2.0 * s * c, (c - s) * (c + s), s, c)


def body_truth(pitch: Trig, roll: Trig, heading: Trig, rates, w_in_n, f_n):
    """The attitude and the body-frame truth of C_b^n = R_z(-heading) R_x(pitch) R_y(roll), from the angles' (N,)
    :func:`trig` (any range: a loop's pitch passes 90 deg) and their ``rates`` (pitch, roll, heading) rad/s:
    ``quat_nb`` (N, 4) scalar-last, unit; ``euler`` (N, 3) [pitch in [-pi/2, pi/2], roll in (-pi, pi], heading
    in [0, 2 pi)] rad, the same attitude; ``omega_ib_b`` = w_nb^b + C_n^b ``w_in_n`` and ``f_ib_b`` = C_n^b
    ``f_n`` (N, 3), rad/s and m/s^2. ``w_in_n`` and ``f_n``: their E, N and U components, three (N,) arrays each
    (an (N, 3) array's transpose will do).

    The matrix is written out from the sines and cosines, and the Euler triple read from the angles in closed
    form (past 90 deg of pitch: pitch pi - gamma, roll and heading turned by pi), so no rotation object is built
    and no angle is recovered from a matrix (which loses digits near 90 deg of pitch). The body vectors are
    formed component by component, each an N-long loop over contiguous arrays, and interleaved once."""
    sp, cp, sr, cr, sh, ch = pitch.sin, pitch.cos, roll.sin, roll.cos, heading.sin, heading.cos
    c = ((ch * cr + sh * sp * sr, sh * cp, ch * sr - sh * sp * cr),          # rows of C_b^n
         (ch * sp * sr - sh * cr, ch * cp, -sh * sr - ch * sp * cr),
         (-cp * sr, sp, cp * cr))

    def to_body(v):  # C_n^b v = (C_b^n)^T v, by component
        e, n, u = v
        return [c[0][j] * e + c[1][j] * n + c[2][j] * u for j in range(3)]

    pitch_dot, roll_dot, heading_dot = rates
    yaw_dot = -heading_dot
    w_nb = (cr * pitch_dot - sr * cp * yaw_dot, sp * yaw_dot + roll_dot,   # as body_rate_nb
            sr * pitch_dot + cr * cp * yaw_dot)
    omega = np.stack([a + b for a, b in zip(w_nb, to_body(w_in_n))], axis=-1)

    # q_z(-heading) q_x(pitch) q_y(roll) written out, as frames.quat_from_euler
    sx, cx, sy, cy, sz, cz = pitch.half_sin, pitch.half_cos, roll.half_sin, roll.half_cos, -heading.half_sin, \
        heading.half_cos
    ax, ay, az, aw = cz * sx, sz * sx, sz * cx, cz * cx
    quat = np.stack([ax * cy - az * sy, aw * sy + ay * cy, ax * sy + az * cy, aw * cy - ay * sy], axis=-1)
    quat /= np.sqrt(np.einsum("ij,ij->i", quat, quat))[:, None]
    s = np.where(cp < 0.0, -1.0, 1.0)
    euler = np.stack([np.arctan2(sp, np.abs(cp)), np.arctan2(s * sr, s * cr),
                      frames.wrap_2pi(np.arctan2(s * sh, s * ch))], axis=-1)
    return quat, euler, omega, np.stack(to_body(f_n), axis=-1)
