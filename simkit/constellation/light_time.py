"""The per-(epoch, satellite) arithmetic of the light-time solution (:func:`simkit.constellation.geometry._emission`
and :func:`~simkit.constellation.geometry.receiver_view`) in compiled passes: the back-propagated iteration from
the state at reception, the last light-time step, and the rotation into the ECEF frame of reception with range
and line of sight. Each carries the same operations in the same order as the array expressions it replaces
(rotation about z by Omega_e tau, norms summed x, y, z), so the results are theirs up to libm's cosine and sine
of angles below 1e-5 rad (tests/test_constellation_light_time.py).
"""
from __future__ import annotations

import math

import numba
import numpy as np

from ..earth import C_LIGHT, OMEGA_E


@numba.njit(cache=True, inline="always", error_model="numpy")
def _rotated(x, y, angle):
    """(x', y') of the frame rotation R_z(angle)."""
    c, s = math.cos(angle), math.sin(angle)
    return c * x + s * y, -s * x + c * y


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _back_iterate(pos, vel, rx, tau_start, iterations, tau):
    for m in range(pos.shape[0]):
        for s in range(pos.shape[1]):
            t = tau_start
            for _ in range(iterations):
                bx, by = _rotated(pos[m, s, 0] - vel[m, s, 0] * t, pos[m, s, 1] - vel[m, s, 1] * t, OMEGA_E * t)
                dx, dy, dz = bx - rx[m, 0], by - rx[m, 1], pos[m, s, 2] - vel[m, s, 2] * t - rx[m, 2]
                t = math.sqrt(dx * dx + dy * dy + dz * dz) / C_LIGHT
                if not math.isfinite(t):
                    t = tau_start
            tau[m, s] = t


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _step(pos, rx, tau, step):
    for m in range(pos.shape[0]):
        for s in range(pos.shape[1]):
            bx, by = _rotated(pos[m, s, 0], pos[m, s, 1], OMEGA_E * tau[m, s])
            dx, dy, dz = bx - rx[m, 0], by - rx[m, 1], pos[m, s, 2] - rx[m, 2]
            new = math.sqrt(dx * dx + dy * dy + dz * dz) / C_LIGHT
            step[m, s] = new - tau[m, s] if math.isfinite(new) else 0.0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _view(pos_e, vel_e, rx, c_en, tau, pos, vel, rng, los, el, az):
    for m in range(pos_e.shape[0]):
        c = c_en[m]
        for s in range(pos_e.shape[1]):
            angle = OMEGA_E * tau[m, s]
            pos[m, s, 0], pos[m, s, 1] = _rotated(pos_e[m, s, 0], pos_e[m, s, 1], angle)
            pos[m, s, 2] = pos_e[m, s, 2]
            if vel.shape[0]:
                vel[m, s, 0], vel[m, s, 1] = _rotated(vel_e[m, s, 0], vel_e[m, s, 1], angle)
                vel[m, s, 2] = vel_e[m, s, 2]
            dx, dy, dz = pos[m, s, 0] - rx[m, 0], pos[m, s, 1] - rx[m, 1], pos[m, s, 2] - rx[m, 2]
            r = math.sqrt(dx * dx + dy * dy + dz * dz)
            u0, u1, u2 = dx / r, dy / r, dz / r
            rng[m, s] = r
            los[m, s, 0], los[m, s, 1], los[m, s, 2] = u0, u1, u2
            up = c[2, 0] * u0 + c[2, 1] * u1 + c[2, 2] * u2
            el[m, s] = math.asin(min(max(up, -1.0), 1.0)) if up == up else up
            az[m, s] = math.atan2(c[0, 0] * u0 + c[0, 1] * u1 + c[0, 2] * u2,
                                  c[1, 0] * u0 + c[1, 1] * u1 + c[1, 2] * u2) % (2.0 * math.pi)


def back_light_time(pos, vel, rx, tau_start: float, iterations: int) -> np.ndarray:
    """Light time (M, S) s to receivers ``rx`` (M, 3) m ECEF of satellites whose state at reception is ``pos``
    (M, S, 3) m, ``vel`` (M, S, 3) m/s (ECEF): ``iterations`` of tau = |R_z(Omega_e tau)(pos - vel tau) - rx| / c
    from ``tau_start``, restarted at ``tau_start`` where not finite."""
    tau = np.empty(pos.shape[:2])
    _back_iterate(*(np.ascontiguousarray(x, dtype=float) for x in (pos, vel, rx)), float(tau_start),
                  int(iterations), tau)
    return tau


def light_time_step(pos, rx, tau) -> np.ndarray:
    """|R_z(Omega_e tau) pos - rx| / c - tau (M, S) s for satellites at emission ``pos`` (M, S, 3) m (ECEF of the
    emission epoch), receivers ``rx`` (M, 3) m; 0 where the new light time is not finite."""
    step = np.empty(pos.shape[:2])
    _step(*(np.ascontiguousarray(x, dtype=float) for x in (pos, rx, tau)), step)
    return step


def rotated_view(pos_e, vel_e, rx, tau, c_en):
    """Satellites at emission (``pos_e`` (M, S, 3) m, ``vel_e`` (M, S, 3) m/s or None, ECEF of emission) rotated
    by Omega_e ``tau`` into the ECEF frame of reception: (pos, vel or None, range (M, S) m, los (M, S, 3) unit
    vectors from receivers ``rx`` (M, 3) m, elevation and azimuth (M, S) rad in the receivers' ENU frames given
    by ``c_en`` (M, 3, 3) (ECEF to ENU), azimuth clockwise from north in [0, 2 pi))."""
    pos_e, rx, tau, c_en = (np.ascontiguousarray(x, dtype=float) for x in (pos_e, rx, tau, c_en))
    vel_e = np.zeros((0, 0, 3)) if vel_e is None else np.ascontiguousarray(vel_e, dtype=float)
    pos, vel = np.empty_like(pos_e), np.empty(vel_e.shape)
    rng, los = np.empty(pos_e.shape[:2]), np.empty_like(pos_e)
    el, az = np.empty(pos_e.shape[:2]), np.empty(pos_e.shape[:2])
    _view(pos_e, vel_e, rx, c_en, tau, pos, vel, rng, los, el, az)
    return pos, (vel if vel.shape[0] else None), rng, los, el, az


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _hermite(k, x, h, pos_g, vel_g, pos, vel):
    for m in range(k.shape[0]):
        xm = x[m]
        x2, x3 = xm * xm, xm * xm * xm
        h00, h10, h01, h11 = 2.0 * x3 - 3.0 * x2 + 1.0, x3 - 2.0 * x2 + xm, 3.0 * x2 - 2.0 * x3, x3 - x2
        d00, d10 = (6.0 * x2 - 6.0 * xm) / h, 3.0 * x2 - 4.0 * xm + 1.0
        d01, d11 = (6.0 * xm - 6.0 * x2) / h, 3.0 * x2 - 2.0 * xm
        g = k[m]
        for s in range(pos_g.shape[1]):
            for i in range(3):
                p0, p1, v0, v1 = pos_g[g, s, i], pos_g[g + 1, s, i], vel_g[g, s, i], vel_g[g + 1, s, i]
                pos[m, s, i] = h00 * p0 + h10 * h * v0 + h01 * p1 + h11 * h * v1
                vel[m, s, i] = d00 * p0 + d10 * v0 + d01 * p1 + d11 * v1


def hermite_states(k, x, h: float, pos_g, vel_g):
    """Positions and velocities (M, S, 3) by cubic Hermite interpolation between the states ``pos_g`` (G, S, 3) m,
    ``vel_g`` (G, S, 3) m/s at nodes ``h`` s apart: epoch m lies at the fraction ``x`` (M,) of the way from node
    ``k`` (M,) int to node k + 1. NaN where either node's state is NaN."""
    k = np.ascontiguousarray(k, dtype=np.int64)
    x, pos_g, vel_g = (np.ascontiguousarray(a, dtype=float) for a in (x, pos_g, vel_g))
    pos, vel = np.empty((k.size,) + pos_g.shape[1:]), np.empty((k.size,) + pos_g.shape[1:])
    _hermite(k, x, float(h), pos_g, vel_g, pos, vel)
    return pos, vel
