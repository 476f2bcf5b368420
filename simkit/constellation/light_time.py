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


@numba.njit(cache=True, error_model="numpy")
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


@numba.njit(cache=True, error_model="numpy")
def _step(pos, rx, tau, step):
    for m in range(pos.shape[0]):
        for s in range(pos.shape[1]):
            bx, by = _rotated(pos[m, s, 0], pos[m, s, 1], OMEGA_E * tau[m, s])
            dx, dy, dz = bx - rx[m, 0], by - rx[m, 1], pos[m, s, 2] - rx[m, 2]
            new = math.sqrt(dx * dx + dy * dy + dz * dz) / C_LIGHT
            step[m, s] = new - tau[m, s] if math.isfinite(new) else 0.0


@numba.njit(cache=True, error_model="numpy")
def _view(pos_e, vel_e, rx, tau, pos, vel, rng, los):
    for m in range(pos_e.shape[0]):
        for s in range(pos_e.shape[1]):
            angle = OMEGA_E * tau[m, s]
            pos[m, s, 0], pos[m, s, 1] = _rotated(pos_e[m, s, 0], pos_e[m, s, 1], angle)
            pos[m, s, 2] = pos_e[m, s, 2]
            if vel.shape[0]:
                vel[m, s, 0], vel[m, s, 1] = _rotated(vel_e[m, s, 0], vel_e[m, s, 1], angle)
                vel[m, s, 2] = vel_e[m, s, 2]
            dx, dy, dz = pos[m, s, 0] - rx[m, 0], pos[m, s, 1] - rx[m, 1], pos[m, s, 2] - rx[m, 2]
            r = math.sqrt(dx * dx + dy * dy + dz * dz)
            rng[m, s] = r
            los[m, s, 0], los[m, s, 1], los[m, s, 2] = dx / r, dy / r, dz / r


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


def rotated_view(pos_e, vel_e, rx, tau):
    """Satellites at emission (``pos_e`` (M, S, 3) m, ``vel_e`` (M, S, 3) m/s or None, ECEF of emission) rotated
    by Omega_e ``tau`` into the ECEF frame of reception: (pos, vel or None, range (M, S) m, los (M, S, 3) unit
    vectors from receivers ``rx`` (M, 3) m)."""
    pos_e, rx, tau = (np.ascontiguousarray(x, dtype=float) for x in (pos_e, rx, tau))
    vel_e = np.zeros((0, 0, 3)) if vel_e is None else np.ascontiguousarray(vel_e, dtype=float)
    pos, vel = np.empty_like(pos_e), np.empty(vel_e.shape)
    rng, los = np.empty(pos_e.shape[:2]), np.empty_like(pos_e)
    _view(pos_e, vel_e, rx, tau, pos, vel, rng, los)
    return pos, (vel if vel.shape[0] else None), rng, los
