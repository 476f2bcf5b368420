"""Numba kernels of the local-level ENU strapdown mechanisation (the recursion behind :func:`strapdown`).

Frames: n = ENU, b = x right / y forward / z up; ``C`` is C_b^n (3, 3). Position is geodetic (lat rad, lon rad,
h m), velocity relative to the Earth in ENU (m/s). Earth rate, transport rate and WGS-84 normal gravity are the
formulas of :mod:`simkit.earth`, written as scalar numba code (a test checks they agree with ``simkit.earth``).

One step integrates one sample interval from the compensated increments (rotation vector ``phi`` (rad) and
sculling-corrected velocity increment ``dvb`` (m/s), both in body axes; see :mod:`.increments`):
    C(k) = exp(-[zeta x]) C(k-1) exp([phi x]),   zeta = w_in^n dt (n-frame rotation over the step)
    v(k) = v(k-1) + (I - [zeta x]/2) C(k-1) dvb + (g^n - (2 w_ie^n + w_en^n) x v_mid) dt
    lat, lon, h: trapezoidal integration of the velocity,
with the Earth-related terms at the mid-interval state extrapolated from the previous step (Savage 2000, ch. 7).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..earth import A, E2, F, GAMMA_E, K_SOMIGLIANA, M_RATIO, OMEGA_E


@njit(cache=True)
def skew(v):
    """[v x] (3, 3) of one vector v (3,): the compiled form of :func:`simkit.frames.skew` that the filter kernels
    call (numba compiles neither that one's stacking over leading axes nor a call back into numpy code)."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


@njit(cache=True)
def cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


@njit(cache=True)
def rotvec_matrix(v):
    """exp([v x]) (Rodrigues: I + a [v x] + b [v x]^2), exact for any angle; written out element by element
    (one allocation: this runs twice per IMU sample)."""
    x, y, z = v[0], v[1], v[2]
    th2 = x * x + y * y + z * z
    if th2 < 1e-12:
        a, b = 1.0 - th2 / 6.0, 0.5 - th2 / 24.0
    else:
        th = np.sqrt(th2)
        a, b = np.sin(th) / th, (1.0 - np.cos(th)) / th2
    m = np.empty((3, 3))
    m[0, 0] = 1.0 - b * (y * y + z * z)
    m[1, 1] = 1.0 - b * (x * x + z * z)
    m[2, 2] = 1.0 - b * (x * x + y * y)
    m[0, 1], m[1, 0] = b * x * y - a * z, b * x * y + a * z
    m[0, 2], m[2, 0] = b * x * z + a * y, b * x * z - a * y
    m[1, 2], m[2, 1] = b * y * z - a * x, b * y * z + a * x
    return m


@njit(cache=True)
def radii(lat):
    """R_M, R_N (m) at geodetic latitude ``lat`` (rad): the formulas of simkit.earth.radii."""
    s2 = np.sin(lat) ** 2
    w = np.sqrt(1.0 - E2 * s2)
    return A * (1.0 - E2) / w**3, A / w


@njit(cache=True)
def gravity(lat, h):
    """WGS-84 normal gravity magnitude (m/s^2): simkit.earth.normal_gravity (TR8350.2 eq. 4-1, 4-3)."""
    s2 = np.sin(lat) ** 2
    g0 = GAMMA_E * (1.0 + K_SOMIGLIANA * s2) / np.sqrt(1.0 - E2 * s2)
    return g0 * (1.0 - 2.0 / A * (1.0 + F + M_RATIO - 2.0 * F * s2) * h + 3.0 * h * h / (A * A))


@njit(cache=True)
def rates(lat, h, v):
    """(w_ie^n, w_en^n) in ENU, rad/s, for velocity ``v`` (ENU, m/s)."""
    rm, rn = radii(lat)
    wie = np.array([0.0, OMEGA_E * np.cos(lat), OMEGA_E * np.sin(lat)])
    wen = np.array([-v[1] / (rm + h), v[0] / (rn + h), v[0] * np.tan(lat) / (rn + h)])
    return wie, wen


@njit(cache=True)
def orthonormalise(c):
    """Nearest rotation matrix (one symmetric correction step, enough at the drift of one step)."""
    e = c @ c.T - np.eye(3)
    return c - 0.5 * (e @ c)


@njit(cache=True)
def step(c, v, pos, v_prev, phi, dvb, dt):
    """One mechanisation step. ``c`` C_b^n, ``v`` ENU velocity, ``pos`` [lat, lon, h] at t(k-1); ``v_prev``
    the velocity one step earlier (for the mid-interval extrapolation). Returns (c, v, pos, dv^n) at t(k)."""
    lat, h = pos[0], pos[2]
    v_mid = v + 0.5 * (v - v_prev)
    rm, rn = radii(lat)
    lat_mid = lat + 0.5 * v_mid[1] / (rm + h) * dt
    h_mid = h + 0.5 * v_mid[2] * dt
    wie, wen = rates(lat_mid, h_mid, v_mid)
    zeta = (wie + wen) * dt
    fn = c @ dvb
    dv_sf = fn - 0.5 * cross(zeta, fn)
    g = np.array([0.0, 0.0, -gravity(lat_mid, h_mid)])
    dv = dv_sf + (g - cross(2.0 * wie + wen, v_mid)) * dt
    v_new = v + dv
    v_avg = 0.5 * (v + v_new)
    rm, rn = radii(lat_mid)
    new = np.empty(3)
    new[2] = h + v_avg[2] * dt
    new[0] = lat + v_avg[1] / (rm + h_mid) * dt
    new[1] = pos[1] + v_avg[0] / ((rn + h_mid) * np.cos(0.5 * (lat + new[0]))) * dt
    c_new = rotvec_matrix(-zeta) @ c @ rotvec_matrix(phi)
    return c_new, v_new, new, dv_sf / dt
