"""Receiver oscillator: two-state (bias, drift) clock model driven by Allan-variance coefficients.

The fractional-frequency noise of an oscillator has the power-law PSD S_y(f) = h0 + h_-1/f + h_-2/f^2. The
two-state model keeps the white-frequency (h0) and random-walk-frequency (h_-2) parts (the flicker term h_-1
has no finite-state form and is omitted); its continuous white-noise PSDs are S_f = h0/2 for the phase (bias) and
S_g = 2 pi^2 h_-2 for the frequency (drift) (Van Dierendonck, McGraw & Brown 1984; Brown & Hwang, Introduction
to Random Signals and Applied Kalman Filtering, 4th ed., 2012, sec. 9.3). Over a step dt the exact discrete
process noise is Q = [[S_f dt + S_g dt^3/3, S_g dt^2/2], [S_g dt^2/2, S_g dt]] (seconds, seconds/second), and the
resulting Allan variance is sigma_y^2(tau) = h0/(2 tau) + (2 pi^2/3) h_-2 tau.

Presets take the h-coefficients of Brown & Hwang Table 9.1 (TCXO: "compensated crystal", OCXO: "ovenized
crystal") plus the initial bias/drift spread a receiver shows after power-up.
"""
from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np


@dataclass(frozen=True)
class Oscillator:
    h0: float               # white-frequency coefficient of S_y(f) (1/Hz)
    h_2: float              # random-walk frequency coefficient (1/Hz^3)
    bias_sigma_s: float     # 1-sigma of the initial clock bias, s
    drift_sigma: float      # 1-sigma of the initial fractional frequency offset (s/s)


PRESETS: dict[str, Oscillator] = {
    "tcxo": Oscillator(h0=2e-19, h_2=2e-20, bias_sigma_s=1e-4, drift_sigma=1e-7),
    "ocxo": Oscillator(h0=8e-20, h_2=4e-23, bias_sigma_s=1e-4, drift_sigma=1e-9),
    "ideal": Oscillator(h0=0.0, h_2=0.0, bias_sigma_s=0.0, drift_sigma=0.0),
}


def process_noise(osc: Oscillator, dt: float) -> np.ndarray:
    """Discrete process-noise covariance (2, 2) of [bias s, drift s/s] over ``dt`` seconds."""
    sf, sg = osc.h0 / 2.0, 2.0 * np.pi**2 * osc.h_2
    return np.array([[sf * dt + sg * dt**3 / 3.0, sg * dt**2 / 2.0], [sg * dt**2 / 2.0, sg * dt]])


def allan_variance(osc: Oscillator, tau) -> np.ndarray:
    """Theoretical Allan variance of the two-state model at averaging times ``tau`` (s)."""
    tau = np.asarray(tau, dtype=float)
    return osc.h0 / (2.0 * tau) + (2.0 * np.pi**2 / 3.0) * osc.h_2 * tau


class ClockProcess:
    """One receiver clock: state [bias s, drift s/s] propagated epoch to epoch at a fixed step ``dt``.

    ``advance(n)`` returns the bias and drift at the next ``n`` epochs (the first call starts with the initial
    state); the draws come from ``rng`` in epoch order, so any split into blocks gives the same arrays.
    """

    def __init__(self, osc: Oscillator, dt: float, rng: np.random.Generator):
        self.dt = float(dt)
        self.rng = rng
        q = process_noise(osc, dt)
        evals, evecs = np.linalg.eigh(q)  # a square root that also works for singular Q (h0 or h_-2 zero)
        self.chol = evecs * np.sqrt(np.clip(evals, 0.0, None))
        self.x = np.array([rng.normal(0.0, osc.bias_sigma_s), rng.normal(0.0, osc.drift_sigma)])
        self.started = False

    def advance(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """(bias (n,) s, drift (n,) s/s) at the next ``n`` epochs."""
        w = self.rng.standard_normal((n, 2)) @ self.chol.T  # (n, 2) process-noise increments
        if not self.started:
            w[0] = 0.0  # epoch 0 is the initial state itself: its draw is spent but not used
            self.x[0] -= self.dt * self.x[1]  # so that the recursion's first step lands on the initial state
            self.started = True
        bias, drift = _propagate(self.x[0], self.x[1], self.dt, w)
        self.x = np.array([bias[-1], drift[-1]])
        return bias, drift


@numba.njit(cache=True, nogil=True)
def _propagate(b, d, dt, w):
    """x_{k+1} = [[1, dt], [0, 1]] x_k + w_k, one step per row of ``w``, sequentially (bit-identical for any
    split of the epochs into blocks)."""
    n = w.shape[0]
    bias = np.empty(n)
    drift = np.empty(n)
    for k in range(n):
        b = b + dt * d + w[k, 0]
        d = d + w[k, 1]
        bias[k] = b
        drift[k] = d
    return bias, drift
