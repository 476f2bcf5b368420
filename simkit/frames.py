"""Frames and attitude: ECEF <-> geodetic (pymap3d, WGS-84), ECEF <-> ENU rotations, Euler <-> rotation.

Conventions (README, "Conventions"): navigation frame n = local-level ENU; body frame b = x right, y forward, z up.
Attitude is the rotation body -> ENU (``scipy.spatial.transform.Rotation``, quaternions scalar-last) built as
C_b^n = R_z(yaw) R_x(pitch) R_y(roll) with yaw = -heading (heading clockwise from north). Euler triples are
ordered [pitch, roll, heading]. Positive pitch is nose up, positive roll is right wing down.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from . import earth

if TYPE_CHECKING:  # imported where used: scipy.spatial costs a truth + IMU run ~0.25 s of start-up it never needs
    from scipy.spatial.transform import Rotation

# ENU <-> NED and body right-forward-up <-> forward-right-down: the same proper rotation (it is its own inverse)
SWAP = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])


def wrap(angle):
    """Angles (rad; a float or an array of any shape) wrapped to [-pi, pi). Plain numpy, so that numba compiles
    this one definition for the filter kernels (``simkit.estimators.model.wrap``) while numpy callers pay no
    compilation (1.8 s cold, 0.6 s from the cache, measured)."""
    return (angle + np.pi) % (2.0 * np.pi) - np.pi


def wrap_2pi(angle):
    """Angles (rad; a float or an array) wrapped to [0, 2 pi): headings and azimuths, clockwise from north.
    Plain numpy, compiled as ``simkit.estimators.model.wrap_2pi`` for the kernels (as :func:`wrap`)."""
    return angle % (2.0 * np.pi)


def skew(v) -> np.ndarray:
    """[v x] (..., 3, 3) of vectors ``v`` (..., 3), any frame and unit: skew(v) @ x == cross(v, x). (The filter
    kernels use the compiled one-vector form ``simkit.estimators.nav.skew``.)"""
    v = np.asarray(v, dtype=float)
    z = np.zeros(v.shape[:-1])
    x, y, w = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([np.stack([z, -w, y], -1), np.stack([w, z, -x], -1), np.stack([-y, x, z], -1)], -2)


def lla_to_ecef(lat, lon, h):
    """Geodetic (rad, rad, m) -> ECEF (..., 3) m."""
    import pymap3d  # imported where used, like scipy.spatial: a truth + IMU run never needs it

    x, y, z = pymap3d.geodetic2ecef(lat, lon, h, ell=earth.ELLIPSOID, deg=False)
    return np.stack(np.broadcast_arrays(x, y, z), axis=-1).astype(float)


def ecef_to_lla(pos):
    """ECEF (..., 3) m -> geodetic (..., 3): lat rad, lon rad, ellipsoidal height m."""
    import pymap3d

    pos = np.asarray(pos, dtype=float)
    lat, lon, h = pymap3d.ecef2geodetic(pos[..., 0], pos[..., 1], pos[..., 2], ell=earth.ELLIPSOID, deg=False)
    return np.stack(np.broadcast_arrays(lat, lon, h), axis=-1).astype(float)


def ecef_to_enu_matrix(lat, lon):
    """Rotation matrices C_e^n (..., 3, 3) taking ECEF vectors to ENU at (lat, lon) in radians.

    Written out because the GNSS stage and the estimators need the matrices themselves (einsum over epochs x
    antennas x satellites, and their rates); pymap3d's ``ecef2enuv`` rotates vectors one call per point set."""
    sl, cl = np.sin(lat), np.cos(lat)
    so, co = np.sin(lon), np.cos(lon)
    z = np.zeros_like(sl * so)
    return np.stack(
        [
            np.stack([-so + z, co + z, z], -1),
            np.stack([-sl * co, -sl * so, cl + z], -1),
            np.stack([cl * co, cl * so, sl + z], -1),
        ],
        -2,
    )


def ecef_to_enu_vec(vec, lat, lon):
    """Rotate ECEF vectors (..., 3) into ENU at (lat, lon)."""
    return np.einsum("...ij,...j->...i", ecef_to_enu_matrix(lat, lon), vec)


def enu_to_ecef_vec(vec, lat, lon):
    """Rotate ENU vectors (..., 3) at (lat, lon) into ECEF."""
    return np.einsum("...ji,...j->...i", ecef_to_enu_matrix(lat, lon), vec)


def quat_from_euler(pitch, roll, heading) -> np.ndarray:
    """Scalar-last quaternions (..., 4) of C_b^n = R_z(-heading) R_x(pitch) R_y(roll), in closed form
    (the product q_z q_x q_y written out; several times faster than a generic Euler conversion)."""
    p2, r2, y2 = np.asarray(pitch, float) / 2, np.asarray(roll, float) / 2, -np.asarray(heading, float) / 2
    sx, cx, sy, cy, sz, cz = np.sin(p2), np.cos(p2), np.sin(r2), np.cos(r2), np.sin(y2), np.cos(y2)
    ax, ay, az, aw = cz * sx, sz * sx, sz * cx, cz * cx  # q_z q_x
    return np.stack([ax * cy - az * sy, aw * sy + ay * cy, ax * sy + az * cy, aw * cy - ay * sy], axis=-1)


def attitude_from_euler(pitch, roll, heading) -> Rotation:
    """Body -> ENU rotation(s) from pitch, roll, heading (rad)."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(quat_from_euler(pitch, roll, heading))


def euler_from_attitude(rot: Rotation) -> np.ndarray:
    """Body -> ENU rotation(s) -> Euler (..., 3) [pitch, roll, heading] rad, heading in [0, 2 pi)."""
    import warnings

    with warnings.catch_warnings():  # gimbal lock at pitch = +-90 deg is a legitimate attitude (loops)
        warnings.simplefilter("ignore", UserWarning)
        yzr = rot.as_euler("ZXY")
    heading = wrap_2pi(-yzr[..., 0])
    return np.stack([yzr[..., 1], yzr[..., 2], heading], axis=-1)


def lever_arm_ecef(pos, vel, quat_nb, omega_ib_b, lever_b):
    """Points at body-frame lever arms ``lever_b`` (A, 3) m from a body at ``pos`` (M, 3) m ECEF moving at ``vel``
    (M, 3) m/s ECEF, with attitude ``quat_nb`` (M, 4) body -> ENU and inertial body rate ``omega_ib_b`` (M, 3)
    rad/s: positions r + C_b^e l and velocities v + C_b^e ((w_ib^b - w_ie^b) x l), both (M, A, 3) ECEF, and C_b^e
    (M, 3, 3)."""
    lla = ecef_to_lla(pos)
    c_en = ecef_to_enu_matrix(lla[:, 0], lla[:, 1])                       # C_e^n (M, 3, 3)
    from scipy.spatial.transform import Rotation

    c_nb = Rotation.from_quat(np.asarray(quat_nb, dtype=float).reshape(-1, 4)).as_matrix()
    c_be = np.einsum("mji,mjk->mik", c_en, c_nb)                          # C_b^e = (C_e^n)^T C_b^n
    w_eb = np.asarray(omega_ib_b, dtype=float).reshape(-1, 3) - np.einsum("mji,j->mi", c_be, earth.EARTH_RATE_ECEF)
    pos_l = pos[:, None, :] + np.einsum("mij,aj->mai", c_be, lever_b)
    vel_l = vel[:, None, :] + np.einsum("mij,maj->mai", c_be, np.cross(w_eb[:, None, :], lever_b[None]))
    return pos_l, vel_l, c_be


def euler_jacobian(rot: Rotation, step: float = 1e-6) -> np.ndarray:
    """(K, 3, 3) derivative of Euler [pitch, roll, heading] (rad) with respect to a small ENU rotation phi (rad),
    C = exp([phi x]) C_b^n, at the K attitudes ``rot`` (body -> ENU), by central differences of ``step`` rad."""
    from scipy.spatial.transform import Rotation

    cols = []
    for axis in np.eye(3):
        d = euler_from_attitude(Rotation.from_rotvec(step * axis) * rot) - euler_from_attitude(
            Rotation.from_rotvec(-step * axis) * rot)
        d[:, 2] = wrap(d[:, 2])  # only the heading can jump by 2 pi; wrapping tiny pitch/roll steps costs bits
        cols.append(d / (2.0 * step))
    return np.stack(cols, axis=-1)


def enu_to_ned(vec):
    """ENU vectors (..., 3) -> NED; the same swap takes body right-forward-up to forward-right-down."""
    return np.asarray(vec, dtype=float) @ SWAP.T


ned_to_enu = enu_to_ned  # the swap is an involution


def attitude_to_ned_frd(rot: Rotation) -> Rotation:
    """Body(RFU) -> ENU attitude -> body(FRD) -> NED attitude, for users of the aerospace convention."""
    from scipy.spatial.transform import Rotation

    s = Rotation.from_matrix(SWAP)
    return s * rot * s


def attitude_from_ned_frd(rot: Rotation) -> Rotation:
    """Body(FRD) -> NED attitude -> body(RFU) -> ENU attitude."""
    return attitude_to_ned_frd(rot)

