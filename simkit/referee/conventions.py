"""Conventions converter: third-party NED / forward-right-down outputs to simkit's ENU / right-forward-up.

simkit: navigation frame ENU, body x right, y forward, z up; attitude body->ENU as a scalar-last quaternion and
Euler [pitch, roll, heading] with C_b^n = R_z(-heading) R_x(pitch) R_y(roll). The aerospace convention (NED,
body x forward, y right, z down, C_b^n = R_z(heading) R_y(pitch) R_x(roll)) describes the same physical
angles: heading clockwise from north, pitch nose up, roll right wing down, so its roll, pitch and heading are
numerically simkit's; only the quaternions and the vector components differ (a swap of the first two axes and a
sign on the third, :data:`simkit.frames.SWAP`).
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from .. import frames
from ..solution import Solution
from .errors import RefereeInputError

FRAMES = ("enu-rfu", "ned-frd")
QUAT_ORDERS = ("xyzw", "wxyz")


def quat_to_simkit(quat, frame: str = "enu-rfu", order: str = "xyzw", where: str = "quat") -> np.ndarray:
    """Quaternions (K, 4) body->navigation in ``frame`` and component ``order`` -> simkit body(RFU)->ENU,
    scalar-last, normalised."""
    if frame not in FRAMES:
        raise RefereeInputError(where, f"frame: expected one of {', '.join(FRAMES)}, got {frame!r}")
    if order not in QUAT_ORDERS:
        raise RefereeInputError(where, f"quaternion order: expected one of {', '.join(QUAT_ORDERS)}, got {order!r}")
    q = np.asarray(quat, dtype=float)
    if q.ndim != 2 or q.shape[1] != 4:
        raise RefereeInputError(where, f"expected shape (K, 4), got {q.shape}")
    rot = Rotation.from_quat(q, scalar_first=(order == "wxyz"))
    return (frames.attitude_from_ned_frd(rot) if frame == "ned-frd" else rot).as_quat()


def euler_from_rph(roll, pitch, heading) -> np.ndarray:
    """(K, 3) simkit Euler [pitch, roll, heading] (rad) from roll, pitch, heading (rad), in either convention."""
    return np.stack([pitch, roll, frames.wrap_2pi(heading)], axis=-1)


def position_ecef(lat=None, lon=None, h=None, ecef=None, where: str = "position") -> np.ndarray | None:
    """ECEF (K, 3) m from geodetic lat, lon (rad), ellipsoidal h (m), or ECEF itself; None when neither."""
    if ecef is not None:
        return np.asarray(ecef, dtype=float)
    if lat is None:
        return None
    lat = np.asarray(lat, dtype=float)
    if np.any(np.abs(lat[np.isfinite(lat)]) > np.pi / 2 + 1e-12):
        raise RefereeInputError(where, "latitude beyond +-90 deg: radians expected (degrees given?)")
    return frames.lla_to_ecef(lat, lon, h)


def solution_from_ned(t, lat, lon, h, vel_ned=None, roll=None, pitch=None, heading=None, sd_ned=None,
                      sd_vel_ned=None, sd_rph=None, config=None) -> Solution:
    """A simkit :class:`Solution` from a NED-convention filter's output: ``t`` (K,) s since the scenario start;
    geodetic ``lat``, ``lon`` (rad), ``h`` (m); ``vel_ned`` (K, 3) m/s; ``roll``, ``pitch``, ``heading`` (K,)
    rad; optional standard deviations ``sd_ned`` (K, 3) m, ``sd_vel_ned`` (K, 3) m/s, ``sd_rph`` (K, 3) rad
    (a diagonal covariance with states pos_n, pos_e, pos_d, vel_n, vel_e, vel_d, roll, pitch, heading)."""
    t = np.asarray(t, dtype=float)
    vel = None if vel_ned is None else frames.ned_to_enu(vel_ned)
    euler = quat = None
    if heading is not None:
        euler = euler_from_rph(roll, pitch, heading)
        quat = frames.quat_from_euler(euler[:, 0], euler[:, 1], euler[:, 2])
    names, sds = [], []
    for prefix, sd in (("pos", sd_ned), ("vel", sd_vel_ned)):
        if sd is not None:
            names += [f"{prefix}_{a}" for a in "ned"]
            sds.append(np.asarray(sd, dtype=float))
    if sd_rph is not None:
        names += ["roll", "pitch", "heading"]
        sds.append(np.asarray(sd_rph, dtype=float))
    cov = None
    if sds:
        var = np.concatenate(sds, axis=1) ** 2
        cov = var[:, :, None] * np.eye(var.shape[1])
    return Solution(t=t, pos_ecef=position_ecef(lat, lon, h), vel_enu=vel, quat_nb=quat, euler=euler, cov=cov,
                    state_names=tuple(names), config=dict(config or {}))
