"""The IMU simulator: truth (body rate, specific force) -> measured gyro / accel and the true error processes.

Per sensor, in this order (body frame x right, y forward, z up):
  signal  = x + (S + M) x + nonlinearity(x) [+ G f for the gyro]        scale factor, misalignment, g-sensitivity
            + vibration                                                 random vibration from a PSD table
  sensed  = lowpass(signal)                                             bandwidth (2nd-order Butterworth)
  y       = sensed + bias + white                                       bias = turn-on + flicker + RRW + Gauss-Markov
  y_sat   = clip(y, -range, range)                                      saturation
  output  = quantize(increment of y_sat) / dt                           quantization of the accumulated increment
Each difference between consecutive stages is one named error term, so output - truth is exactly their sum.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..rng import generator
from .config import VIBRATION_KEYS, ImuConfig, SensorSpec
from .noise import Flicker, LowPass, Quantizer, RandomWalk, WhiteNoise, gauss_markov
from .vibration import Vibration


@dataclass(frozen=True)
class ImuBlock:
    """One block of IMU output.

    ``gyro`` (N, 3) rad/s and ``accel`` (N, 3) m/s^2 are the measured rates; ``dtheta`` (N, 3) rad and ``dvel``
    (N, 3) m/s the measured increments (``imu.output = "increments"``, else None); ``errors`` maps each error
    term (``gyro_bias``, ``accel_white``, ...) to its (N, 3) true values: gyro - truth = sum of the gyro_* terms.
    """

    gyro: np.ndarray
    accel: np.ndarray
    dtheta: np.ndarray | None
    dvel: np.ndarray | None
    errors: dict[str, np.ndarray]


def truth_increments(x: np.ndarray, prev: np.ndarray | None, dt: float) -> np.ndarray:
    """Integral of the sampled truth over each interval (t[k-1], t[k]].

    Exact integration of the quadratic through the samples k-2, k-1, k: dt (-x[k-2] + 8 x[k-1] + 5 x[k]) / 12;
    the trapezoid for the second sample of the record and dt x[0] (constant extrapolation) for the very first.
    ``prev`` holds the last (up to two) samples before this block (None or empty at the start of the record).
    """
    hist = x[:0] if prev is None else prev
    lag, n = hist.shape[0], x.shape[0]
    head = np.concatenate([hist, x])               # output j uses head[lag + j - 2 : lag + j + 1]
    out = np.empty_like(x)
    j0 = min(max(0, 2 - lag), n)                   # first output with two samples before it
    out[j0:] = dt * (-head[lag + j0 - 2:lag + n - 2] + 8.0 * head[lag + j0 - 1:lag + n - 1]
                     + 5.0 * head[lag + j0:]) / 12.0
    if lag == 0 and n > 0:
        out[0] = dt * x[0]
    if lag <= 1 and n > 1 - lag:
        j = 1 - lag
        out[j] = dt * 0.5 * (head[lag + j - 1] + head[lag + j])
    return out


def _apply(matrix: np.ndarray, x: np.ndarray) -> np.ndarray:
    """x @ matrix.T elementwise: unlike BLAS, the rounding does not depend on the block length. Column by column
    (N-long loops: broadcasting (N, 1) against (3,) runs N loops of 3, 3.5x slower; the same sums)."""
    out = np.empty_like(x)
    for j in range(3):
        out[:, j] = x[:, 0] * matrix[j, 0] + x[:, 1] * matrix[j, 1] + x[:, 2] * matrix[j, 2]
    return out


class _Sensor:
    """State of one sensor triad (gyro or accel) across blocks."""

    def __init__(self, name: str, spec: SensorSpec, dt: float, seed: int, increments: bool):
        self.name, self.spec, self.dt, self.increments = name, spec, dt, increments

        def rng(*term):
            return generator(seed, "imu", name, *term)

        s = spec
        self.turn_on = s.bias_turn_on * rng("bias_turn_on").standard_normal(3) if s.bias_turn_on > 0 else None
        matrix = np.zeros((3, 3))
        if s.scale_factor > 0:
            matrix[np.diag_indices(3)] = s.scale_factor * rng("scale_factor").standard_normal(3)
        if s.misalignment > 0:
            off = ~np.eye(3, dtype=bool)
            matrix[off] = s.misalignment * rng("misalignment").standard_normal(6)
        self.matrix = matrix if (s.scale_factor > 0 or s.misalignment > 0) else None
        self.g_matrix = (s.g_sensitivity * rng("g_sensitivity").standard_normal((3, 3))
                         if name == "gyro" and s.g_sensitivity > 0 else None)
        self.bias_sources = []
        if s.bias_instability > 0:
            self.bias_sources.append(Flicker(s.bias_instability, s.bias_instability_tau_min_s,
                                             s.bias_instability_tau_max_s, dt, rng("bias_instability")))
        if s.rate_random_walk > 0:
            self.bias_sources.append(RandomWalk(s.rate_random_walk, dt, rng("rate_random_walk")))
        for i, gm in enumerate(s.gauss_markov):
            if gm.sigma > 0:
                self.bias_sources.append(gauss_markov(gm.sigma, gm.tau_s, dt, rng("gauss_markov", str(i))))
        self.white = WhiteNoise(s.random_walk, dt, rng("white")) if s.random_walk > 0 else None
        self.vibration = (Vibration(np.array(s.vibration_psd), dt, rng("vibration"),
                                    f"imu.{name}.{VIBRATION_KEYS[name][0]}") if s.vibration_psd else None)
        nyquist = 0.5 / dt
        self.lowpass = LowPass(s.bandwidth_hz, dt) if 0 < s.bandwidth_hz < nyquist else None
        self.quantizer = Quantizer(s.quantization) if s.quantization > 0 else None
        self.prev = None  # last two truth samples, for increments
        self.drawn: list[tuple] = []  # drawn ahead (draw_ahead), in order: (samples, vibration, bias, white)

    def _draw(self, n: int) -> tuple:
        """The next ``n`` samples of the terms that do not depend on the truth: (n, vibration, bias, white), each
        (n, 3) or None when the sensor has no such term; bias = turn-on + its sources."""
        vibration = self.vibration.block(n) if self.vibration is not None else None
        bias = None
        if self.turn_on is not None or self.bias_sources:
            bias = np.broadcast_to(self.turn_on if self.turn_on is not None else 0.0, (n, 3)).copy()
            for src in self.bias_sources:
                bias += src.block(n)
        return n, vibration, bias, self.white.block(n) if self.white is not None else None

    def draw_ahead(self, n: int) -> None:
        """Draw the truth-independent terms of the next ``n`` samples now (each term's own stream, so the record
        is the same samples whenever they are drawn); :meth:`process` uses them first."""
        if n > 0 and (self.vibration is not None or self.turn_on is not None or self.bias_sources
                      or self.white is not None):
            self.drawn.append(self._draw(n))

    def _terms(self, n: int) -> tuple:
        """(vibration, bias, white) of the next ``n`` samples: those drawn ahead first, then fresh draws."""
        parts, have = [], 0
        while self.drawn and have < n:
            m, *terms = self.drawn.pop(0)
            if have + m > n:  # keep the rest for the next block (views: nothing writes into these arrays)
                cut = n - have
                self.drawn.insert(0, (m - cut, *(None if x is None else x[cut:] for x in terms)))
                terms, m = [None if x is None else x[:cut] for x in terms], cut
            parts.append(terms)
            have += m
        if have < n:
            parts.append(self._draw(n - have)[1:])
        if len(parts) == 1:
            return tuple(parts[0])
        return tuple(None if p[0] is None else np.concatenate(p) for p in zip(*parts))

    def process(self, x: np.ndarray, f: np.ndarray):
        """Measured rates (N, 3), error terms {name: (N, 3)} and, in increments mode, the measured increments."""
        s, n, errors = self.spec, x.shape[0], {}
        signal = x
        if self.matrix is not None or s.scale_factor_nonlinearity > 0:
            e = _apply(self.matrix, x) if self.matrix is not None else np.zeros_like(x)
            if s.scale_factor_nonlinearity > 0:
                e = e + s.scale_factor_nonlinearity / s.range * x * np.abs(x)
            errors["scale_misalignment"] = e
            signal = signal + e
        if self.g_matrix is not None:
            errors["g_sensitivity"] = _apply(self.g_matrix, f)
            signal = signal + errors["g_sensitivity"]
        vibration, bias, white = self._terms(n)
        if vibration is not None:
            errors["vibration"] = vibration
            signal = signal + vibration
        y = signal
        if self.lowpass is not None:
            y = self.lowpass.block(signal)
            errors["bandwidth"] = y - signal
        if bias is not None:
            errors["bias"] = bias
            y = y + bias
        if white is not None:
            errors["white"] = white
            y = y + white
        if s.range > 0:
            clipped = np.clip(y, -s.range, s.range)
            errors["saturation"] = clipped - y
            y = clipped
        increments = None
        if self.increments:
            true_inc = truth_increments(x, self.prev, self.dt)
            self.prev = np.concatenate([self.prev if self.prev is not None else x[:0], x])[-2:].copy()
            raw = true_inc + self.dt * (y - x)
            increments = self.quantizer.block(raw) if self.quantizer is not None else raw
            out = increments / self.dt
            if self.quantizer is not None:
                errors["quantization"] = (increments - raw) / self.dt
        elif self.quantizer is not None:
            out = self.quantizer.block(self.dt * y) / self.dt
            errors["quantization"] = out - y
        else:
            out = y
        return out, {f"{self.name}_{k}": v for k, v in errors.items()}, increments


class ImuSimulator:
    """Streams IMU measurements from truth, block by block, at ``rate_hz`` with random streams from ``seed``.

    Call :meth:`process` on consecutive blocks of the truth; the output does not depend on how the record is cut.
    """

    def __init__(self, cfg: ImuConfig, rate_hz: float, seed: int):
        if not rate_hz > 0:
            raise ValueError(f"rate_hz must be > 0, got {rate_hz!r}")
        self.cfg, self.rate_hz, self.dt = cfg, float(rate_hz), 1.0 / float(rate_hz)
        inc = cfg.output == "increments"
        self.gyro = _Sensor("gyro", cfg.gyro, self.dt, seed, inc)
        self.accel = _Sensor("accel", cfg.accel, self.dt, seed, inc)

    def draw_ahead(self, n: int) -> None:
        """Draw the noise of the next ``n`` samples (the terms that do not depend on the truth) now, e.g. while
        the truth is computed elsewhere; the output is the same as without."""
        self.gyro.draw_ahead(n)
        self.accel.draw_ahead(n)

    def process(self, t: np.ndarray, omega_ib_b: np.ndarray, f_ib_b: np.ndarray) -> ImuBlock:
        """Measure one block of truth.

        t (N,) s since start (consecutive samples at the IMU rate), omega_ib_b (N, 3) rad/s, f_ib_b (N, 3) m/s^2,
        body frame. Returns gyro (N, 3) rad/s, accel (N, 3) m/s^2 and errors {name: (N, 3)} with
        gyro - omega_ib_b == sum of the "gyro_*" terms (likewise accel). In increments mode gyro / accel are the
        measured increments divided by dt, the truth they differ from is the integral of the truth over each
        interval divided by dt (:func:`truth_increments`), and ``dtheta`` (rad) / ``dvel`` (m/s) hold them.
        """
        omega = np.asarray(omega_ib_b, dtype=float)
        f = np.asarray(f_ib_b, dtype=float)
        if omega.shape != f.shape or omega.ndim != 2 or omega.shape[1] != 3 or np.shape(t) != omega.shape[:1]:
            raise ValueError(f"expected t (N,), omega_ib_b and f_ib_b (N, 3); got {np.shape(t)}, "
                             f"{omega.shape}, {f.shape}")
        gyro, gerr, dtheta = self.gyro.process(omega, f)
        accel, aerr, dvel = self.accel.process(f, f)
        return ImuBlock(gyro=gyro, accel=accel, dtheta=dtheta, dvel=dvel, errors={**gerr, **aerr})

    def attributes(self) -> dict:
        """Model parameters (resolved preset + overrides, SI units) and the run's random constants, JSON-ready."""
        attrs = self.cfg.attributes()
        attrs["rate_hz"] = self.rate_hz
        for s in (self.gyro, self.accel):
            drawn = {}
            if s.turn_on is not None:
                drawn["bias_turn_on"] = s.turn_on.tolist()
            if s.matrix is not None:
                drawn["scale_misalignment_matrix"] = s.matrix.tolist()
            if s.g_matrix is not None:
                drawn["g_sensitivity_matrix"] = s.g_matrix.tolist()
            attrs[s.name]["drawn"] = drawn
        return attrs
