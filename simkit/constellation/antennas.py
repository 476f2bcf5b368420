"""What each antenna of a rigid body sees, from the light-time solution at the body's reference point.

The reference solution (IMU centre, :func:`simkit.constellation.receiver_view`) gives the satellite at emission
``X0`` (ECEF frame at reception) and the light time ``tau0``. An antenna a lever arm away receives a signal
emitted ``d`` seconds earlier or later; over those nanoseconds the satellite moves inertially, so
X(d) = X0 - V d with V its inertial velocity expressed in the reception frame (error below 1e-12 m for baselines
of tens of metres). The range rate is the exact derivative of the light-time range in the inertial frame aligned
with ECEF at reception: rho' = u.(V - v_r) / (1 + u.V / c), v_r the antenna's inertial velocity.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import earth, frames
from ..earth import C_LIGHT, EARTH_RATE_ECEF
from .geometry import angles_from_enu



@dataclass(frozen=True)
class AntennaView:
    """Per antenna a and satellite s, at M epochs (arrays (M, A, S) unless stated).

    ``range`` m and ``range_rate`` m/s (geometric, light time and Earth rotation included); ``los`` (M, A, S, 3)
    unit vectors antenna -> satellite in ECEF; ``elevation``, ``azimuth`` rad (ENU of the antenna, azimuth
    clockwise from north) and their rates rad/s; ``sat_clock`` s and ``sat_drift`` s/s at each antenna's emission
    time; ``up_rate`` (M, A) m/s the antenna's vertical (ellipsoid-normal) velocity.
    """

    range: np.ndarray
    range_rate: np.ndarray
    los: np.ndarray
    elevation: np.ndarray
    azimuth: np.ndarray
    elevation_rate: np.ndarray
    azimuth_rate: np.ndarray
    sat_clock: np.ndarray
    sat_drift: np.ndarray
    lla: np.ndarray
    vel_enu: np.ndarray


def antenna_view(ref: dict, ant_pos: np.ndarray, ant_vel: np.ndarray) -> AntennaView:
    """Refine the reference light-time solution ``ref`` (``sat_pos``, ``sat_vel``, ``tau``, ``sat_clock``,
    ``sat_drift`` as (M, S[, 3]), see :meth:`simkit.constellation.Sky.view`) to antennas at ``ant_pos`` (M, A, 3)
    m moving at ``ant_vel`` (M, A, 3) m/s, both ECEF."""
    x0 = ref["sat_pos"][:, None]                                   # (M, 1, S, 3), ECEF frame at reception
    v_in = ref["sat_vel"][:, None] + np.cross(EARTH_RATE_ECEF, x0)          # inertial velocity in that frame
    r = ant_pos[:, :, None, :]
    d = _extra_light_time(x0, v_in, ref["tau"][:, None], r)
    diff = x0 - v_in * d[..., None] - r
    rng = np.linalg.norm(diff, axis=-1)
    u = diff / rng[..., None]
    v_r = ant_vel[:, :, None, :] + np.cross(EARTH_RATE_ECEF, r)
    rr = np.einsum("masi,masi->mas", u, v_in - v_r) / (1.0 + np.einsum("masi,masi->mas", u, v_in) / C_LIGHT)
    el, az, el_rate, az_rate, lla, vel_enu = _angles(u, rng, ref["sat_vel"][:, None] - ant_vel[:, :, None, :],
                                                     ant_pos, ant_vel)
    clock = ref["sat_clock"][:, None] - ref["sat_drift"][:, None] * d
    drift = np.broadcast_to(ref["sat_drift"][:, None], clock.shape)
    return AntennaView(rng, rr, u, el, az, el_rate, az_rate, clock, drift, lla, vel_enu)


def _extra_light_time(x0, v_in, tau0, r, iterations: int = 2):
    """Light time to each antenna minus the reference light time (s); each iteration gains a factor v/c."""
    d = np.zeros(np.broadcast_shapes(tau0.shape, r.shape[:-1]))
    for _ in range(iterations):
        d = np.linalg.norm(x0 - v_in * d[..., None] - r, axis=-1) / C_LIGHT - tau0
    return d


def _angles(u, rng, rel_vel, ant_pos, ant_vel):
    """Elevation and azimuth (rad) of the lines of sight ``u`` (M, A, S, 3) at each antenna, and their rates
    (rad/s) from the line-of-sight rate in ECEF (rotating-frame relative velocity ``rel_vel`` (M, A, S, 3)); the
    antennas' geodetic position (M, A, 3) and ENU velocity (M, A, 3) m/s."""
    u_dot = (rel_vel - u * np.einsum("masi,masi->mas", u, rel_vel)[..., None]) / rng[..., None]
    lla = frames.ecef_to_lla(ant_pos.reshape(-1, 3)).reshape(ant_pos.shape)
    c_en = frames.ecef_to_enu_matrix(lla[..., 0], lla[..., 1])    # (M, A, 3, 3)
    vel_enu = np.einsum("maij,maj->mai", c_en, ant_vel)
    # the antenna's ENU axes turn relative to ECEF at the transport rate: d(C_e^n u)/dt = C_e^n u' - w_en x (C_e^n u)
    w_en = earth.transport_rate_enu(lla[..., 0], lla[..., 2], vel_enu)
    enu = np.einsum("maij,masj->masi", c_en, u)
    enu_dot = np.einsum("maij,masj->masi", c_en, u_dot) - np.cross(w_en[:, :, None, :], enu)
    el_rate = enu_dot[..., 2] / np.sqrt(np.maximum(1.0 - enu[..., 2] ** 2, 1e-12))
    hz = enu[..., 0] ** 2 + enu[..., 1] ** 2
    az_rate = (enu[..., 1] * enu_dot[..., 0] - enu[..., 0] * enu_dot[..., 1]) / np.maximum(hz, 1e-12)
    el, az = angles_from_enu(enu)
    return el, az, el_rate, az_rate, lla, vel_enu
