"""Initialisation: coarse alignment from static data, or in motion from GNSS velocity.

* ``static_alignment``: accelerometer levelling (the mean specific force is -g rotated into the body:
  pitch = asin(f_y / |f|), roll = atan2(-f_x, f_z)) plus gyrocompassing (the mean rate is the Earth rate in
  body axes: the north row of C_b^n is (w^b - u^b W sin L) / (W cos L), u^b the up row). The heading is
  meaningful only when the gyro bias is well below W cos L (15 deg/h cos L); the returned heading sigma says so.
* ``motion_alignment``: heading and pitch from the GNSS velocity (body y along the velocity, as simkit's
  trajectories fly), roll 0.
Angles in rad; C_b^n = R_z(-heading) R_x(pitch) R_y(roll).
"""
from __future__ import annotations

import numpy as np

from ..earth import OMEGA_E
from ..frames import wrap_2pi
from .errors import EstimatorInputError


def static_alignment(gyro, accel, lat, gyro_bias_sigma=0.0):
    """Mean of static samples ``gyro`` (N, 3) rad/s, ``accel`` (N, 3) m/s^2 at latitude ``lat`` rad ->
    (euler [pitch, roll, heading] rad, heading sigma rad from the gyro bias sigma)."""
    w, f = np.mean(gyro, axis=0), np.mean(accel, axis=0)
    g = np.linalg.norm(f)
    if not g > 5.0:
        raise EstimatorInputError(f"static alignment: mean specific force {g:.2f} m/s^2, expected about 9.8")
    up = f / g
    north = (w - up * OMEGA_E * np.sin(lat)) / (OMEGA_E * np.cos(lat))
    north -= up * (north @ up)
    north /= np.linalg.norm(north)
    east = np.cross(north, up)
    c = np.vstack([east, north, up])  # rows: E, N, U in body axes -> C_b^n
    pitch = np.arcsin(np.clip(c[2, 1], -1, 1))
    roll = np.arctan2(-c[2, 0], c[2, 2])
    heading = wrap_2pi(np.arctan2(c[0, 1], c[1, 1]))
    return np.array([pitch, roll, heading]), gyrocompass_heading_sigma(gyro_bias_sigma, lat)


def gyrocompass_heading_sigma(gyro_sigma, lat) -> float:
    """Heading sigma (rad) of gyrocompassing with a gyro error ``gyro_sigma`` rad/s (bias, noise over the span) at
    latitude ``lat`` rad: that error read as a tilt of the horizontal Earth rate Omega_e cos(lat)."""
    return float(np.arctan2(gyro_sigma, OMEGA_E * np.cos(lat)))


def motion_alignment(vel_enu):
    """Euler [pitch, roll, heading] (rad) from a velocity (3,) ENU m/s of at least 5 m/s."""
    v = np.asarray(vel_enu, float)
    horiz = np.hypot(v[0], v[1])
    if not horiz > 5.0:
        raise EstimatorInputError(f"motion alignment: horizontal speed {horiz:.2f} m/s, expected > 5 m/s")
    return np.array([np.arctan2(v[2], horiz), 0.0, wrap_2pi(np.arctan2(v[0], v[1]))])
