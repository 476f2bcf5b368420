"""Random vibration from a PSD table: a streaming generator, identical whatever the block cut.

Convention: vibration tables are ONE-sided PSDs (as in MIL-STD-810 random-vibration profiles), SI units here
((m/s^2)^2/Hz or (rad/s)^2/Hz), interpolated piecewise linearly in log-log between the table points and zero
outside the table. The variance (RMS^2) is the integral of the one-sided PSD over the table.

Unit white noise filtered by a linear-phase FIR h has one-sided PSD 2 dt |H(f)|^2, so the filter's amplitude
response is sqrt(S(f) fs / 2). h is designed by frequency sampling (scipy.signal.firwin2) and scaled so that
sum(h^2) equals the table's exact variance.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import ScenarioError

# Filter length: this many frequency bins of fs / taps below the lowest table frequency (window smearing of the
# lower band edge then stays a small fraction of the first band).
TAPS_PER_LOWEST_BIN = 16
MIN_TAPS = 257
MAX_TAPS = 1 << 18
# White noise is drawn and filtered in fixed frames of this many filter lengths (at least 2^14 samples).
FRAME_TAPS = 4


def psd_at(table: np.ndarray, f: np.ndarray) -> np.ndarray:
    """One-sided PSD of ``table`` ((M, 2): increasing f in Hz, PSD > 0) at ``f``: log-log interpolation, 0 outside."""
    f = np.asarray(f, dtype=float)
    out = np.zeros_like(f)
    inside = (f >= table[0, 0]) & (f <= table[-1, 0])
    out[inside] = np.exp(np.interp(np.log(f[inside]), np.log(table[:, 0]), np.log(table[:, 1])))
    return out


def band_variance(table: np.ndarray) -> np.ndarray:
    """Exact integral of the log-log interpolated PSD over each band [f_i, f_i+1] (MIL-STD-810 Grms formula)."""
    f1, f2 = table[:-1, 0], table[1:, 0]
    s1, s2 = table[:-1, 1], table[1:, 1]
    r = np.log(f2 / f1)
    slope = np.log(s2 / s1) / r                     # exponent of S ~ f^slope within the band
    e = slope + 1.0
    # s1 f1 ((f2/f1)^e - 1) / e, written with expm1 so it tends to s1 f1 ln(f2/f1) as e -> 0
    return s1 * f1 * np.where(np.abs(e * r) > 1e-12, np.expm1(e * r) / np.where(e == 0, 1.0, e), r)


def design(table: np.ndarray, fs: float, key: str) -> np.ndarray:
    """FIR taps (odd count, linear phase) turning unit white noise into vibration of one-sided PSD ``table``.

    ``key`` names the scenario key in the errors (table above Nyquist, lowest frequency too low for the rate).
    """
    nyquist = 0.5 * fs
    if table[-1, 0] > nyquist:
        raise ScenarioError(key, f"frequency {table[-1, 0]:g} Hz is above the Nyquist frequency "
                                 f"{nyquist:g} Hz of the {fs:g} Hz IMU rate")
    taps = max(MIN_TAPS, int(math.ceil(TAPS_PER_LOWEST_BIN * fs / table[0, 0])) | 1)
    if taps > MAX_TAPS:
        raise ScenarioError(key, f"lowest frequency {table[0, 0]:g} Hz is too low for the {fs:g} Hz IMU rate "
                                 f"(needs a {taps}-tap filter, at most {MAX_TAPS}): raise it")
    from scipy.signal import firwin2  # here: scipy.signal costs ~1 s of start-up, and most runs have no vibration

    grid = np.linspace(0.0, nyquist, 1 + (1 << int(math.ceil(math.log2(taps)))))
    h = firwin2(taps, grid, np.sqrt(psd_at(table, grid) * nyquist), fs=fs)
    return h * math.sqrt(band_variance(table).sum() / np.sum(h * h))


class Vibration:
    """Vibration of one-sided PSD ``table`` ((M, 2) Hz, SI^2/Hz) on ``axes`` independent axes, block by block.

    White noise is drawn in fixed frames aligned to the record start and filtered by FFT (overlap-save with the
    last taps-1 inputs as state); the output is buffered and handed out per block, so any cut of the record gives
    bit-identical samples. The filter is primed with taps-1 draws: stationary from the first sample.
    Memory O(taps * axes).
    """

    def __init__(self, table: np.ndarray, dt: float, rng: np.random.Generator, key: str, axes: int = 3):
        from scipy import fft  # here: only a vibrating IMU needs it

        self.h = design(np.asarray(table, dtype=float), 1.0 / dt, key)
        self.rng, self.axes = rng, axes
        taps = self.h.size
        self.frame = max(1 << 14, FRAME_TAPS * taps)
        self.nfft = fft.next_fast_len(self.frame + taps - 1, real=True)
        self.kernel = fft.rfft(self.h, self.nfft)[:, None]
        self.history = rng.standard_normal((taps - 1, axes))
        self.ready = np.empty((0, axes))

    def _next_frame(self) -> np.ndarray:
        w = np.concatenate([self.history, self.rng.standard_normal((self.frame, self.axes))])
        self.history = w[self.frame:]
        from scipy import fft

        y = fft.irfft(fft.rfft(w, self.nfft, axis=0) * self.kernel, self.nfft, axis=0)
        return y[self.h.size - 1:self.h.size - 1 + self.frame]

    def block(self, count: int) -> np.ndarray:
        parts, have = [self.ready], self.ready.shape[0]
        while have < count:
            parts.append(self._next_frame())
            have += self.frame
        merged = np.concatenate(parts) if len(parts) > 1 else self.ready
        self.ready = merged[count:].copy()
        return merged[:count]
