"""Smooth command profiles: the time functions that drive the vehicle's kinematic channels.

A profile returns its value and its first time derivative at an array of absolute times (s), zero outside its
support. Every profile starts and ends at zero with zero slope (quintic smoothstep ramps), so commands are C1
at every segment join and the specific force and body rates built from them have no steps (jerk-limited).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def smoothstep(x):
    """Quintic smoothstep S(x) = 10x^3 - 15x^4 + 6x^5 on [0, 1] (S' = S'' = 0 at both ends) and its slope."""
    x = np.clip(x, 0.0, 1.0)
    s = x**3 * (10.0 + x * (-15.0 + 6.0 * x))
    ds = 30.0 * x**2 * (1.0 - x) ** 2
    return s, ds


def envelope(tau, duration: float, ramp: float):
    """Smooth 0 -> 1 -> 0 window over tau in [0, duration] with ramps of ``ramp`` s, and its slope.

    Requires ramp <= duration / 2 so the rising and falling ramps never overlap.
    """
    up, dup = smoothstep(tau / ramp)
    down, ddown = smoothstep((duration - tau) / ramp)
    inside = (tau >= 0.0) & (tau <= duration)
    return np.where(inside, up * down, 0.0), np.where(inside, (dup * down - up * ddown) / ramp, 0.0)


@dataclass(frozen=True)
class Plateau:
    """A rate that ramps from 0 to ``value`` in ``ramp`` s, holds, and ramps back to 0 by ``start + duration``.

    Its integral over the support is exactly ``value * (duration - ramp)``.
    """

    start: float
    duration: float
    ramp: float
    value: float

    @staticmethod
    def for_change(start: float, change: float, rate: float, ramp: float) -> "Plateau":
        """The plateau at |rate| (sign from ``change``) whose integral is ``change``.

        Short changes shrink the ramp so that the plateau keeps its rate (triangle-like profile).
        """
        rate = abs(rate) * np.sign(change) if change else 0.0
        if change == 0.0:
            return Plateau(start, 0.0, ramp, 0.0)
        hold = change / rate
        ramp = min(ramp, hold)
        return Plateau(start, hold + ramp, ramp, rate)

    @property
    def end(self) -> float:
        return self.start + self.duration

    def integral(self) -> float:
        """The integral over the whole support (exact)."""
        return self.value * (self.duration - self.ramp) if self.duration > 0.0 else 0.0

    def evaluate(self, t):
        if self.duration <= 0.0 or self.value == 0.0:
            z = np.zeros(np.shape(t))
            return z, z.copy()
        env, denv = envelope(np.asarray(t, dtype=float) - self.start, self.duration, self.ramp)
        return self.value * env, self.value * denv


@dataclass(frozen=True)
class Sinusoid:
    """``amplitude * sin(2 pi (t - start) / period)`` under a smooth envelope that rises and falls in ``ramp`` s."""

    start: float
    duration: float
    ramp: float
    amplitude: float
    period: float

    @property
    def end(self) -> float:
        return self.start + self.duration

    def evaluate(self, t):
        tau = np.asarray(t, dtype=float) - self.start
        env, denv = envelope(tau, self.duration, self.ramp)
        w = 2.0 * np.pi / self.period
        s, c = np.sin(w * tau), np.cos(w * tau)
        return self.amplitude * env * s, self.amplitude * (denv * s + env * w * c)

    def integral(self) -> float:
        """The integral over the whole support, in closed form.

        With w = 2 pi / period, r the ramp and d the duration: the rising ramp contributes r J(w r), the plateau
        int_r^(d-r) sin(w u) du, and the falling ramp (substituting u = d - r x) r e^(i w d) conj(J(w r)), where
        J is :func:`smoothstep_fourier`; the sine integral is the imaginary part of their sum.
        """
        w, r, d = 2.0 * np.pi / self.period, self.ramp, self.duration
        j = smoothstep_fourier(w * r)
        ramps = np.imag(r * j + r * np.exp(1j * w * d) * np.conj(j))
        plateau = (np.cos(w * r) - np.cos(w * (d - r))) / w
        return self.amplitude * float(ramps + plateau)


_S_DERIVS_AT_1 = (1.0, 0.0, 0.0, 60.0, 360.0, 720.0)   # S^(k)(1), k = 0..5
_S_DERIVS_AT_0 = (0.0, 0.0, 0.0, 60.0, -360.0, 720.0)  # S^(k)(0)


def smoothstep_fourier(theta: float) -> complex:
    """J(theta) = int_0^1 S(x) e^(i theta x) dx for the quintic smoothstep S, theta > 0, to full precision.

    theta >= 4: repeated integration by parts, finite since S is a quintic,
    J = sum_k (-1)^k (e^(i theta) S^(k)(1) - S^(k)(0)) / (i theta)^(k+1).
    theta < 4 (where those terms cancel): the power series sum_n (i theta)^n / n! m_n with the exact moments
    m_n = int_0^1 x^n S(x) dx = 10 / (n+4) - 15 / (n+5) + 6 / (n+6); 40 terms reach 4^40 / 40! < 1e-23.
    """
    if theta >= 4.0:
        e = np.exp(1j * theta)
        return complex(sum((-1.0) ** k * (e * s1 - s0) / (1j * theta) ** (k + 1)
                           for k, (s1, s0) in enumerate(zip(_S_DERIVS_AT_1, _S_DERIVS_AT_0))))
    n = np.arange(40)
    moments = 10.0 / (n + 4) - 15.0 / (n + 5) + 6.0 / (n + 6)
    coef = np.cumprod(np.concatenate([[1.0 + 0j], 1j * theta / n[1:]]))   # (i theta)^n / n!
    return complex(np.sum(coef * moments))
