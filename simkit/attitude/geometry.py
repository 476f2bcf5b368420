"""Receiver position from code (single-point, vectorised over epochs) and lines of sight in ENU.

Only the line-of-sight directions and elevations need the receiver position here: a position error of 10 m
turns a line of sight by ~5e-7 rad (5 um over a 10 m baseline), so a code solution without atmospheric models
is ample. Satellite positions are those of the file (ECEF of the transmit epoch); the Earth rotation during the
signal's travel (Sagnac) is applied here by rotating them into the ECEF frame of the receive epoch.
"""
from __future__ import annotations

import numpy as np

from ..constellation.geometry import lines_of_sight_enu, sagnac_rotate
from ..earth import C_LIGHT


def code_position(code: np.ndarray, sat_pos: np.ndarray, sat_clock: np.ndarray, iterations: int = 8) -> np.ndarray:
    """Single-point position (M, 3) m ECEF from code (M, S) m, satellites (M, S, 3) m and clocks (M, S) s.

    Unweighted Gauss-Newton on all epochs at once, unknowns position and receiver clock: ``iterations`` from the
    Earth's centre on every 60th epoch, then 3 on every epoch from the nearest of those. NaN rows where fewer
    than 4 satellites have code. No ionosphere / troposphere model (metres of error).
    """
    ok = np.isfinite(code) & np.isfinite(sat_pos).all(-1) & np.isfinite(sat_clock)
    rho = np.where(ok, code + C_LIGHT * np.nan_to_num(sat_clock), 0.0)
    sp, w = np.nan_to_num(sat_pos), ok.astype(float)
    coarse = np.arange(0, len(code), 60)
    x = _gauss_newton(rho[coarse], sp[coarse], w[coarse], np.zeros((len(coarse), 4)), iterations)
    x = np.nan_to_num(x[np.minimum(np.arange(len(code)) // 60, len(coarse) - 1)])
    x = _gauss_newton(rho, sp, w, x, 3)
    x[ok.sum(1) < 4] = np.nan
    return x[:, :3]


def _gauss_newton(rho, sp, w, x, iterations):
    """Iterations of the code least squares from x (M, 4) [position m, clock m]."""
    for _ in range(iterations):
        s = sagnac_rotate(sp, x[:, :3])
        d = s - x[:, None, :3]
        r = np.linalg.norm(d, axis=-1)
        H = np.concatenate([-d / np.where(r > 0, r, 1.0)[..., None], np.ones(r.shape + (1,))], axis=-1)
        Hw = H * w[..., None]
        N = np.swapaxes(Hw, 1, 2) @ H + 1e-9 * np.eye(4)
        g = np.swapaxes(Hw, 1, 2) @ (rho - r - x[:, 3:4])[..., None]
        x = x + np.linalg.solve(N, g)[..., 0]
    return x


def lines_of_sight(receiver: np.ndarray, sat_pos: np.ndarray):
    """Unit lines of sight receiver -> satellite in ENU (M, S, 3) and elevations (M, S) rad, Sagnac applied."""
    return lines_of_sight_enu(receiver, sagnac_rotate(sat_pos, receiver))
