"""Time-differenced carrier-phase (TDCP) velocity of one antenna (Badshah 2015 eqs 15-24), arrays in and out.

Between receiver epochs j-1 and j the ambiguity cancels (no slip), and for each satellite s (ECEF, Sagnac
applied, unit line of sight e from the receiver):

    z_s = lambda dphi_s + c d(dt_s) - (rho_hat_j - rho_hat_{j-1}) = -e_j . (dr - dr_hat) + c d(dt_r),

after removing the modelled troposphere (Saastamoinen with the mapping of simkit.gnss.atmosphere at the code
position; it changes by cm/s on a climb), with rho_hat from the code position of epoch j-1 moved by dr_hat (iterated), so z is linear in [dr, c d(dt_r)]
(four unknowns, at least 5 satellites for the residual test). Slips: LLI set at either epoch drops the
difference; afterwards the largest normalised residual above ``slip_threshold`` is dropped and the epoch re-solved
(up to 3 times). Velocity = dr / dt in ENU (m/s), attributed to the middle of the interval.
"""
from __future__ import annotations

import numpy as np

from ..constellation.geometry import sagnac_rotate
from ..earth import C_LIGHT


def _lsq(H, z, w):
    """Batched weighted least squares: x (K, 4), residuals (K, R)."""
    N = np.einsum("kri,kr,krj->kij", H, w, H) + 1e-12 * np.eye(H.shape[-1])
    x = np.linalg.solve(N, np.einsum("kri,kr,kr->ki", H, w, z)[..., None])[..., 0]
    return x, z - np.einsum("kri,ki->kr", H, x)


def tdcp_velocity(phase_m, usable, sat_pos, sat_clock, receiver, dt, sigma_m=0.003, slip_threshold=5.0,
                  iterations=3, delay_m=None):
    """Antenna displacement per interval from carrier (K+1 epochs).

    ``phase_m`` (K+1, R) carrier in metres, R = rows (signal, satellite); ``usable`` (K, R) bool (tracked at both
    epochs, no LLI); ``sat_pos`` (K+1, R, 3) m ECEF (transmit frame), ``sat_clock`` (K+1, R) s; ``receiver``
    (K+1, 3) m ECEF approximate; ``dt`` (K,) s; ``delay_m`` (K+1, R) modelled atmospheric delays removed
    from the phase (e.g. troposphere; None: none). Returns (velocity (K, 3) m/s ECEF, clock drift (K,) m/s, used
    (K, R) bool after slip rejection, residual rms (K,) m); NaN where fewer than 5 rows remain.
    """
    s = sagnac_rotate(sat_pos, receiver)
    x0 = receiver[:-1]
    dr = np.zeros_like(x0)
    w = usable.astype(float)
    phase_m = phase_m if delay_m is None else phase_m - delay_m
    z_carrier = np.nan_to_num(phase_m[1:] - phase_m[:-1]) + C_LIGHT * np.nan_to_num(sat_clock[1:] - sat_clock[:-1])
    rho0 = np.linalg.norm(s[:-1] - x0[:, None], axis=-1)
    for _ in range(iterations + 3):
        d1 = s[1:] - (x0 + dr)[:, None]
        rho1 = np.linalg.norm(d1, axis=-1)
        H = np.concatenate([-d1 / rho1[..., None], np.ones(rho1.shape + (1,))], -1)
        z = np.nan_to_num(z_carrier - (rho1 - rho0))
        x, v = _lsq(H, z, w)
        dr = dr + x[:, :3]
        bad = np.abs(v) * w > slip_threshold * sigma_m
        worst = np.argmax(np.abs(v) * w, axis=1)
        drop = bad[np.arange(len(w)), worst]
        w[np.flatnonzero(drop), worst[drop]] = 0.0
    x, v = _lsq(H, z, w)
    n = w.sum(1)
    clock = x[:, 3] + 0.0
    rms = np.sqrt((v * v * w).sum(1) / np.maximum(n - 4, 1))
    vel = dr / dt[:, None]
    vel[n < 5], clock[n < 5], rms[n < 5] = np.nan, np.nan, np.nan
    return vel, clock / dt, w > 0, rms
