"""Multipath: first-order Gauss-Markov processes per antenna, satellite and signal, scaled with elevation.

The unit-variance process x_{k+1} = phi x_k + sqrt(1 - phi^2) w_k, phi = exp(-dt / tau), is stationary and
exactly discretised for any step. The error is sigma(el) x with sigma(el) = sigma_horizon exp(-el / el0): large
near the horizon, small at zenith (the exponential elevation profile of Kee & Parkinson-type multipath models).
"""
from __future__ import annotations

import numpy as np
from scipy.signal import lfilter


def elevation_scale(el, sigma_horizon, el0_rad):
    """Multipath standard deviation at elevation ``el`` (rad)."""
    return sigma_horizon * np.exp(-np.asarray(el) / el0_rad)


class GaussMarkov:
    """A bank of independent unit-variance first-order Gauss-Markov processes, advanced block by block.

    ``advance(w)`` takes standard-normal driving noise ``w`` (n, ...) in epoch order and returns the process at
    those n epochs; the first epoch of the first call is the stationary initial value sqrt(1) w_0.
    """

    def __init__(self, dt: float, tau: float, shape: tuple):
        self.phi = float(np.exp(-dt / tau))
        self.gain = float(np.sqrt(1.0 - self.phi**2))
        self.state = None
        self.shape = shape

    def advance(self, w: np.ndarray) -> np.ndarray:
        n = w.shape[0]
        w = w.reshape(n, -1)
        if self.state is None:
            # stationary start: x_0 = w_0, then the recursion
            x0 = w[0]
            rest = w[1:]
            out = np.empty_like(w)
            out[0] = x0
            if n > 1:
                out[1:], _ = lfilter([self.gain], [1.0, -self.phi], rest, axis=0, zi=(self.phi * x0)[None, :])
        else:
            out, _ = lfilter([self.gain], [1.0, -self.phi], w, axis=0, zi=(self.phi * self.state)[None, :])
        self.state = out[-1].copy()
        return out.reshape((n,) + self.shape)
