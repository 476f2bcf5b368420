"""An independent strapdown integrator, used only by the tests to check the truth's inertial consistency.

It works in ECEF (the generator works in local-level ENU), with a quaternion C_b^e, and integrates the sampled
w_ib^b and f_ib^b with classical RK4, so its
own error is O(h^4). Midpoint samples come from 4-point Lagrange interpolation of the samples, so the step is
one sample interval. Gravity: WGS-84 normal gravity (TR8350.2 eq. 4-1, 4-3) written out again here.
"""
import numpy as np
from numba import njit

A, F = 6378137.0, 1 / 298.257223563
E2 = F * (2 - F)
W = 7.292115e-5
GE, K = 9.7803253359, 0.00193185265241
M = 0.00344978650684


@njit(cache=True)
def _geodetic(r):
    x, y, z = r
    p = np.sqrt(x * x + y * y)
    lon = np.arctan2(y, x)
    lat = np.arctan2(z, p * (1 - E2))
    h = 0.0
    for _ in range(8):
        s = np.sin(lat)
        n = A / np.sqrt(1 - E2 * s * s)
        h = p / np.cos(lat) - n
        lat = np.arctan2(z, p * (1 - E2 * n / (n + h)))
    return lat, lon, h


@njit(cache=True)
def _gravity(r):
    lat, lon, h = _geodetic(r)
    s2 = np.sin(lat) ** 2
    g = GE * (1 + K * s2) / np.sqrt(1 - E2 * s2)
    g *= 1 - 2 / A * (1 + F + M - 2 * F * s2) * h + 3 * h * h / A**2
    cl, sl, co, so = np.cos(lat), np.sin(lat), np.cos(lon), np.sin(lon)
    return -g * np.array([cl * co, cl * so, sl])


@njit(cache=True)
def _qmul(a, b):  # scalar-last Hamilton product
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return np.array([aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz])


@njit(cache=True)
def _rotate(q, v):
    qv = np.array([v[0], v[1], v[2], 0.0])
    qc = np.array([-q[0], -q[1], -q[2], q[3]])
    return _qmul(_qmul(q, qv), qc)[:3]


@njit(cache=True)
def _deriv(q, r, v, w_ib, f_b):
    we = np.array([0.0, 0.0, W])
    qdot = 0.5 * (_qmul(q, np.array([w_ib[0], w_ib[1], w_ib[2], 0.0]))
                  - _qmul(np.array([0.0, 0.0, W, 0.0]), q))
    vdot = _rotate(q, f_b) + _gravity(r) - 2 * np.cross(we, v)
    return qdot, v.copy(), vdot


def midpoints(x):
    """Values halfway between samples (rows of ``x``), by 4-point Lagrange (3-point at the two ends)."""
    mid = np.empty((len(x) - 1,) + x.shape[1:])
    mid[1:-1] = (-x[:-3] + 9 * x[1:-2] + 9 * x[2:-1] - x[3:]) / 16
    mid[0] = (3 * x[0] + 6 * x[1] - x[2]) / 8
    mid[-1] = (-x[-3] + 6 * x[-2] + 3 * x[-1]) / 8
    return mid


def integrate(q0, r0, v0, omega, force, h):
    """RK4 with step h over samples spaced h; returns q (scalar-last C_b^e), r, v at every sample."""
    return _integrate(q0, r0, v0, omega, midpoints(omega), force, midpoints(force), h)


@njit(cache=True)
def _integrate(q0, r0, v0, omega, omega_mid, force, force_mid, h):
    n = omega.shape[0] - 1
    qs = np.empty((n + 1, 4))
    rs = np.empty((n + 1, 3))
    vs = np.empty((n + 1, 3))
    q, r, v = q0.copy(), r0.copy(), v0.copy()
    qs[0], rs[0], vs[0] = q, r, v
    dt = h
    for i in range(n):
        w0, w1, w2 = omega[i], omega_mid[i], omega[i + 1]
        f0, f1, f2 = force[i], force_mid[i], force[i + 1]
        k1q, k1r, k1v = _deriv(q, r, v, w0, f0)
        k2q, k2r, k2v = _deriv(q + 0.5 * dt * k1q, r + 0.5 * dt * k1r, v + 0.5 * dt * k1v, w1, f1)
        k3q, k3r, k3v = _deriv(q + 0.5 * dt * k2q, r + 0.5 * dt * k2r, v + 0.5 * dt * k2v, w1, f1)
        k4q, k4r, k4v = _deriv(q + dt * k3q, r + dt * k3r, v + dt * k3v, w2, f2)
        q = q + dt / 6 * (k1q + 2 * k2q + 2 * k3q + k4q)
        q /= np.sqrt(np.sum(q * q))
        r = r + dt / 6 * (k1r + 2 * k2r + 2 * k3r + k4r)
        v = v + dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        qs[i + 1], rs[i + 1], vs[i + 1] = q, r, v
    return qs, rs, vs
