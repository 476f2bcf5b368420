"""IMU-centre velocity from an antenna velocity and the lever arm (Badshah 2015 eqs 15-24 with the lever arm).

The antenna at lever arm l (body, m) from the IMU centre: r_ant^e = r_imu^e + C_b^e l, so over a TDCP interval
(t0, t1] the mean IMU velocity is the antenna's minus the lever arm's turn,

    v_imu = v_ant - (C_b^e(t1) l - C_b^e(t0) l) / dt          (differenced attitude, exact for the mean),

or, from a body rate, v_imu = v_ant - C_b^n (w_eb^b x l), w_eb^b = w_ib^b - C_n^b w_ie^n (IMU rate minus the
Earth rate; the transport rate, < 1e-4 rad/s, is left out). Vectors here in ENU of the interval's first epoch;
R = C_b^n (K, 3, 3), E = C_e^n (K, 3, 3) (rows E, N, U of the local ENU frame in ECEF). Attitude errors are the
ENU small rotation phi of docs/attitude.md (R_true = exp([phi x]) R, so d(R l) = -[(R l) x] phi).
"""
from __future__ import annotations

import numpy as np

from ..earth import OMEGA_E
from ..frames import skew


def lever_velocity_differenced(R0, R1, E0, E1, lever_b, dt, P0=None, P1=None):
    """Mean velocity (K, 3) m/s in ENU of epoch 0 of the lever arm over (t0, t1] from the attitudes R0, R1 at both
    ends (ENU frames E0, E1), and its covariance (K, 3, 3) from the attitude-error covariances P0, P1 (K, 3, 3)
    rad^2 taken as independent (an upper bound when the attitude errors are correlated in time); 0 when None."""
    u0 = R0 @ lever_b
    u1 = np.einsum("kij,klj,kl->ki", E0, E1, R1 @ lever_b)  # E0 E1' R1 l
    dt = np.asarray(dt, float)[:, None]
    v = (u1 - u0) / dt
    cov = np.zeros(v.shape + (3,))
    if P0 is not None:
        A0 = skew(u0)
        A1 = E0 @ np.swapaxes(E1, 1, 2) @ skew(R1 @ lever_b)
        cov = (A0 @ P0 @ np.swapaxes(A0, 1, 2) + A1 @ P1 @ np.swapaxes(A1, 1, 2)) / dt[..., None] ** 2
    return v, cov


def lever_velocity_rate(R, omega_ib_b, lat, lever_b, P=None, cov_omega=None):
    """Velocity (K, 3) m/s in ENU of the lever arm, C_b^n (w_eb^b x l), from the attitude R (K, 3, 3), the body
    rate w_ib^b (K, 3) rad/s and the latitude (K,) rad; covariance (K, 3, 3) from the attitude error P (K, 3, 3)
    rad^2 and the rate error covariance ``cov_omega`` (K, 3, 3) (rad/s)^2 (0 when None)."""
    w_ie = np.stack([np.zeros_like(lat), OMEGA_E * np.cos(lat), OMEGA_E * np.sin(lat)], -1)
    w_eb = omega_ib_b - np.einsum("kji,kj->ki", R, w_ie)
    v = np.einsum("kij,kj->ki", R, np.cross(w_eb, lever_b))
    cov = np.zeros(v.shape + (3,))
    if P is not None:
        B = skew(v)
        cov = cov + B @ P @ np.swapaxes(B, 1, 2)
    if cov_omega is not None:
        C = -R @ skew(np.broadcast_to(lever_b, v.shape))  # d v / d w = R [(-l) x]
        cov = cov + C @ cov_omega @ np.swapaxes(C, 1, 2)
    return v, cov


def tdcp_velocity_covariance(los_enu, used, sigma_m, dt):
    """Covariance (K, 3, 3) (m/s)^2 of the TDCP velocity in ENU: the position block of (H' H)^-1 2 sigma^2 / dt^2,
    H rows [-e, 1] of the ``used`` (K, S) satellites (``los_enu`` (K, S, 3) unit receiver -> satellite), every
    time difference of two undifferenced carriers of sd ``sigma_m``; NaN with fewer than 5 rows."""
    H = np.concatenate([-los_enu, np.ones(los_enu.shape[:-1] + (1,))], -1)
    w = used.astype(float)
    N = np.einsum("kri,kr,krj->kij", np.nan_to_num(H), w, np.nan_to_num(H))
    ok = w.sum(1) >= 5
    N[~ok] = np.eye(4)
    cov = np.linalg.inv(N)[:, :3, :3] * (2 * sigma_m ** 2) / np.asarray(dt, float)[:, None, None] ** 2
    cov[~ok] = np.nan
    return cov
