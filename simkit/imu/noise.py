"""Streaming generators of the stochastic IMU error processes, per axis, block by block.

Each generator draws from its own random stream in sample-major order and carries its state between blocks, so a
record cut into any blocks is bit-identical to the record made in one call. A sample represents the interval
(t[k-1], t[k]] of length ``dt``; every discretisation below is exact (or accurate to O(dt/tau)) for the continuous
process, so the same physical spec gives the same Allan deviation at any sample rate. The first-order
Gauss-Markov bias terms use the bank shared with the GNSS multipath, :class:`simkit.processes.GaussMarkov`.
"""
from __future__ import annotations

import math

import numba
import numpy as np
from scipy import signal

# Flicker band: correlation times log-spaced at this many per decade (ripple of the ADEV floor < 1 %).
FLICKER_POLES_PER_DECADE = 2
# Flicker poles faster than 1 / (this * dt) are dropped: the shared-noise discretisation is accurate for p*dt <= 0.1.
FLICKER_MIN_TAU_SAMPLES = 10.0


class WhiteNoise:
    """White noise of two-sided PSD ``n**2`` averaged over each sample interval: sample std ``n / sqrt(dt)``."""

    def __init__(self, n: float, dt: float, rng: np.random.Generator, axes: int = 3):
        self.std, self.rng, self.axes = n / math.sqrt(dt), rng, axes

    def block(self, count: int) -> np.ndarray:
        return self.std * self.rng.standard_normal((count, self.axes))


class RandomWalk:
    """Rate random walk: integrated white noise of two-sided PSD ``k**2``, sampled at the interval ends.

    Starts at zero (the turn-on bias carries the initial offset). Its Allan variance is
    ``k^2 tau / 3 + k^2 dt^2 / (6 tau)``: the sampling term is below 0.5 % beyond ten samples.
    """

    def __init__(self, k: float, dt: float, rng: np.random.Generator, axes: int = 3):
        self.step, self.rng = k * math.sqrt(dt), rng
        self.value = np.zeros((1, axes))

    def block(self, count: int) -> np.ndarray:
        steps = self.step * self.rng.standard_normal((count, self.value.shape[1]))
        out = np.cumsum(np.concatenate([self.value, steps]), axis=0)[1:]
        self.value = out[-1:].copy()
        return out


def flicker_design(b: float, tau_min: float, tau_max: float, dt: float):
    """Poles p_i (1/s) and partial-fraction weights c_i of the flicker shaping filter.

    H(s) = g * prod_i (s + z_i) / (s + p_i) * 1 / (s + p_M) with poles log-spaced over [1/tau_max, 1/tau_min] and a
    zero at the geometric mean of each pair of adjacent poles, so |H(j w)|^2 ~ 1/w inside the band. Its partial
    fractions H(s) = sum_i c_i / (s + p_i) make the process a sum of first-order Gauss-Markov processes driven by
    one common unit white noise; g is set so that the two-sided PSD equals B^2 / (2 pi f) in the band (IEEE 952),
    i.e. the Allan floor is 0.664 B.
    """
    tau_min = max(tau_min, FLICKER_MIN_TAU_SAMPLES * dt)
    decades = math.log10(tau_max / tau_min)
    m = max(2, int(round(decades * FLICKER_POLES_PER_DECADE)) + 1)
    p = np.logspace(-math.log10(tau_max), -math.log10(tau_min), m)
    z = np.sqrt(p[:-1] * p[1:])
    c = np.array([np.prod(z - pi) / np.prod(np.delete(p, i) - pi) for i, pi in enumerate(p)])
    # calibrate on the central part of the band, away from the edges
    w = np.logspace(math.log10(p[1]), math.log10(p[-2]), 64) if m > 3 else np.sqrt(p[:1] * p[-1:])
    h2 = np.abs(np.sum(c[None, :] / (1j * w[:, None] + p[None, :]), axis=1)) ** 2
    gain = b / math.sqrt(math.exp(np.mean(np.log(w * h2))))
    return p, gain * c


@numba.njit(cache=True)
def _flicker_kernel(w, phi, u, c, state, out):  # pragma: no cover - compiled
    n, axes = w.shape
    m = phi.shape[0]
    for k in range(n):
        for a in range(axes):
            acc = 0.0
            for i in range(m):
                s = phi[i] * state[i, a] + u[i] * w[k, a]
                state[i, a] = s
                acc += c[i] * s
            out[k, a] = acc


class Flicker:
    """Bias instability as flicker (1/f) noise of IEEE coefficient ``b`` over correlation times [tau_min, tau_max].

    Sum of first-order Gauss-Markov branches sharing one white noise (see :func:`flicker_design`): one normal
    draw per sample and axis, memory O(branches), started from the stationary distribution. Each branch is
    x_k = exp(-p dt) x_{k-1} + (1 - exp(-p dt)) / p * w_k with w_k the interval mean of the unit white noise.
    """

    def __init__(self, b: float, tau_min: float, tau_max: float, dt: float, rng: np.random.Generator,
                 axes: int = 3):
        p, self.c = flicker_design(b, tau_min, tau_max, dt)
        self.phi = np.exp(-p * dt)
        self.u = -np.expm1(-p * dt) / p / math.sqrt(dt)
        cov = 1.0 / (p[:, None] + p[None, :])       # stationary covariance of the branches, unit white input
        vals, vecs = np.linalg.eigh(cov)
        root = vecs * np.sqrt(np.clip(vals, 0.0, None))
        self.state = root @ rng.standard_normal((p.size, axes))
        self.rng = rng

    def block(self, count: int) -> np.ndarray:
        w = self.rng.standard_normal((count, self.state.shape[1]))
        out = np.empty_like(w)
        _flicker_kernel(w, self.phi, self.u, self.c, self.state, out)
        return out


@numba.njit(cache=True)
def _quantize_kernel(v, step, residual, out):  # pragma: no cover - compiled
    n, axes = v.shape
    for a in range(axes):
        r = residual[a]
        for k in range(n):
            x = r + v[k, a]
            q = math.floor(x / step + 0.5) * step
            r = x - q
            out[k, a] = q
        residual[a] = r


class Quantizer:
    """Quantises increments to multiples of ``step`` carrying the remainder (an accumulating counter's output).

    The accumulated angle / velocity is rounded, so the increment error is the difference of two rounding errors:
    IEEE quantization noise with Q = step / sqrt(12) and Allan variance 3 Q^2 / tau^2.
    """

    def __init__(self, step: float, axes: int = 3):
        self.step = step
        self.residual = np.zeros(axes)

    def block(self, increments: np.ndarray) -> np.ndarray:
        out = np.empty_like(increments)
        _quantize_kernel(np.ascontiguousarray(increments), self.step, self.residual, out)
        return out


class LowPass:
    """Second-order Butterworth low-pass at ``cutoff_hz`` (bilinear, pre-warped), started in steady state."""

    def __init__(self, cutoff_hz: float, dt: float):
        self.sos = signal.butter(2, cutoff_hz, fs=1.0 / dt, output="sos")
        self.zi = None

    def block(self, x: np.ndarray) -> np.ndarray:
        if self.zi is None:
            self.zi = signal.sosfilt_zi(self.sos)[:, :, None] * x[:1][None, :, :]
        y, self.zi = signal.sosfilt(self.sos, x, axis=0, zi=self.zi)
        return y
