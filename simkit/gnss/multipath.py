"""Multipath: first-order Gauss-Markov processes per antenna, satellite and signal, scaled with elevation.

The unit-variance process x_{k+1} = phi x_k + sqrt(1 - phi^2) w_k, phi = exp(-dt / tau), is stationary and
exactly discretised for any step. The error is sigma(el) x with sigma(el) = sigma_horizon exp(-el / el0): large
near the horizon, small at zenith (the exponential elevation profile of Kee & Parkinson-type multipath models).
"""
from __future__ import annotations

import numba
import numpy as np


def elevation_scale(el, sigma_horizon, el0_rad):
    """Multipath standard deviation at elevation ``el`` (rad)."""
    return sigma_horizon * np.exp(-np.asarray(el) / el0_rad)


class GaussMarkov:
    """A bank of unit-variance first-order Gauss-Markov processes (A, S, G, 2), advanced block by block.

    A process restarts from its stationary distribution (x = w) at each (re)acquisition of its satellite:
    multipath after an outage is independent of what it was before. Only the visible satellites' columns are
    advanced; the recursion runs epoch by epoch (numba), so any block split gives the same values.
    """

    def __init__(self, dt: float, tau: float, shape: tuple):
        self.phi = float(np.exp(-dt / tau))
        self.gain = float(np.sqrt(1.0 - self.phi**2))
        self.state = np.zeros(shape)

    def advance(self, w: np.ndarray, restart: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """``w`` (M, A, C, G, 2) standard normals for satellite columns ``cols`` (C,), ``restart`` (M, A, C)."""
        m, a, c = restart.shape
        x0 = self.state[:, cols].reshape(-1)
        k = w[0].size // (a * c)
        flags = np.repeat(restart.reshape(m, a * c), k, axis=1)
        x = _recursion(w.reshape(m, -1), flags, x0, self.phi, self.gain)
        self.state[:, cols] = x[-1].reshape(self.state[:, cols].shape)
        return x.reshape(w.shape)


@numba.njit(cache=True)
def _recursion(w, restart, x0, phi, gain):
    m, n = w.shape
    out = np.empty((m, n))
    x = x0.copy()
    for k in range(m):
        for i in range(n):
            x[i] = w[k, i] if restart[k, i] else phi * x[i] + gain * w[k, i]
            out[k, i] = x[i]
    return out
