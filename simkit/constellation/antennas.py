"""What each antenna of a rigid body sees, from the light-time solution at the body's reference point.

The reference solution (IMU centre, :func:`simkit.constellation.receiver_view`) gives the satellite at emission
``X0`` (ECEF frame at reception) and the light time ``tau0``. An antenna a lever arm away receives a signal
emitted ``d`` seconds earlier or later; over those nanoseconds the satellite moves inertially, so
X(d) = X0 - V d with V its inertial velocity expressed in the reception frame (error below 1e-12 m for baselines
of tens of metres). The range rate is the exact derivative of the light-time range in the inertial frame aligned
with ECEF at reception: rho' = u.(V - v_r) / (1 + u.V / c), v_r the antenna's inertial velocity.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from .. import earth, frames
from ..earth import C_LIGHT, OMEGA_E


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
    m moving at ``ant_vel`` (M, A, 3) m/s, both ECEF.

    The antennas' geodetic position, ENU axes and transport rate are arrays over (M, A); the per-satellite work
    (extra light time, range, range rate, angles and their rates) is one compiled pass over (M, A, S)."""
    ant_pos, ant_vel = (np.ascontiguousarray(x, dtype=float) for x in (ant_pos, ant_vel))
    lla = frames.ecef_to_lla(ant_pos.reshape(-1, 3)).reshape(ant_pos.shape)
    c_en = np.ascontiguousarray(frames.ecef_to_enu_matrix(lla[..., 0], lla[..., 1]))    # (M, A, 3, 3)
    vel_enu = np.einsum("maij,maj->mai", c_en, ant_vel)
    w_en = earth.transport_rate_enu(lla[..., 0], lla[..., 2], vel_enu)
    sat = [np.ascontiguousarray(ref[k], dtype=float) for k in ("sat_pos", "sat_vel", "tau", "sat_clock",
                                                                 "sat_drift")]
    m, n_ant, n_sat = ant_pos.shape[0], ant_pos.shape[1], sat[0].shape[1]
    out = [np.empty((m, n_ant, n_sat)) for _ in range(7)]
    los = np.empty((m, n_ant, n_sat, 3))
    _per_satellite(*sat, ant_pos, ant_vel, c_en, np.ascontiguousarray(w_en), EXTRA_LIGHT_TIME_ITERATIONS, *out,
                   los)
    rng, rr, el, az, el_rate, az_rate, clock = out
    drift = np.broadcast_to(sat[4][:, None], clock.shape)
    return AntennaView(rng, rr, los, el, az, el_rate, az_rate, clock, drift, lla, vel_enu)


EXTRA_LIGHT_TIME_ITERATIONS = 2  # light time to each antenna minus the reference one: each gains a factor v/c


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _per_satellite(x0, sat_vel, tau0, clock0, drift0, ant_pos, ant_vel, c_en, w_en, iterations,
                   rng, rr, el, az, el_rate, az_rate, clock, los):
    om = OMEGA_E
    for m in range(ant_pos.shape[0]):
        for a in range(ant_pos.shape[1]):
            r0, r1, r2 = ant_pos[m, a, 0], ant_pos[m, a, 1], ant_pos[m, a, 2]
            # the antenna's inertial velocity in the ECEF axes of reception: v + w_ie x r
            vr0, vr1, vr2 = ant_vel[m, a, 0] - om * r1, ant_vel[m, a, 1] + om * r0, ant_vel[m, a, 2]
            c = c_en[m, a]
            w0, w1, w2 = w_en[m, a, 0], w_en[m, a, 1], w_en[m, a, 2]
            for s in range(x0.shape[1]):
                x_0, x_1, x_2 = x0[m, s, 0], x0[m, s, 1], x0[m, s, 2]
                sv0, sv1, sv2 = sat_vel[m, s, 0], sat_vel[m, s, 1], sat_vel[m, s, 2]
                v0, v1, v2 = sv0 - om * x_1, sv1 + om * x_0, sv2            # inertial velocity, same axes
                d = 0.0
                for _ in range(iterations):
                    e0, e1, e2 = x_0 - v0 * d - r0, x_1 - v1 * d - r1, x_2 - v2 * d - r2
                    d = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2) / C_LIGHT - tau0[m, s]
                e0, e1, e2 = x_0 - v0 * d - r0, x_1 - v1 * d - r1, x_2 - v2 * d - r2
                rho = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
                u0, u1, u2 = e0 / rho, e1 / rho, e2 / rho
                rng[m, a, s] = rho
                los[m, a, s, 0], los[m, a, s, 1], los[m, a, s, 2] = u0, u1, u2
                rr[m, a, s] = (u0 * (v0 - vr0) + u1 * (v1 - vr1) + u2 * (v2 - vr2)) / \
                    (1.0 + (u0 * v0 + u1 * v1 + u2 * v2) / C_LIGHT)
                clock[m, a, s] = clock0[m, s] - drift0[m, s] * d
                # line-of-sight rate in ECEF from the rotating-frame relative velocity, then ENU and its rate
                q0, q1, q2 = sv0 - ant_vel[m, a, 0], sv1 - ant_vel[m, a, 1], sv2 - ant_vel[m, a, 2]
                uq = u0 * q0 + u1 * q1 + u2 * q2
                ud0, ud1, ud2 = (q0 - u0 * uq) / rho, (q1 - u1 * uq) / rho, (q2 - u2 * uq) / rho
                n0 = c[0, 0] * u0 + c[0, 1] * u1 + c[0, 2] * u2
                n1 = c[1, 0] * u0 + c[1, 1] * u1 + c[1, 2] * u2
                n2 = c[2, 0] * u0 + c[2, 1] * u1 + c[2, 2] * u2
                # d(C_e^n u)/dt = C_e^n u' - w_en x (C_e^n u)
                nd0 = c[0, 0] * ud0 + c[0, 1] * ud1 + c[0, 2] * ud2 - (w1 * n2 - w2 * n1)
                nd1 = c[1, 0] * ud0 + c[1, 1] * ud1 + c[1, 2] * ud2 - (w2 * n0 - w0 * n2)
                nd2 = c[2, 0] * ud0 + c[2, 1] * ud1 + c[2, 2] * ud2 - (w0 * n1 - w1 * n0)
                el_rate[m, a, s] = nd2 / math.sqrt(max(1.0 - n2 ** 2, 1e-12))
                az_rate[m, a, s] = (n1 * nd0 - n0 * nd1) / max(n0 ** 2 + n1 ** 2, 1e-12)
                el[m, a, s] = math.asin(min(max(n2, -1.0), 1.0)) if n2 == n2 else n2
                az[m, a, s] = math.atan2(n0, n1) % (2.0 * math.pi)
