"""C/N0 model and thermal-noise (tracking jitter) standard deviations.

C/N0 (dB-Hz) = cn0_zenith_dbhz + signal offset + antenna gain(theta), where theta is the angle between the
line of sight and the antenna boresight and the gain pattern is G(theta) = -rolloff_db * (theta / 90 deg)^2 (0 dB
at boresight, -rolloff_db at the antenna horizon). For a level antenna theta = 90 deg - elevation.

Tracking-loop thermal noise (Kaplan & Hegarty, Understanding GPS/GNSS, 3rd ed., 2017, sec. 8.7 and 8.8),
with c = C/N0 in Hz (linear), B loop bandwidths (Hz), T coherent integration time (s), d early-late spacing (chips):
* DLL (early-minus-late power, BPSK):  sigma = L_chip sqrt(B_dll d / (2 c) (1 + 2 / (T c (2 - d))))   [m]
* PLL (Costas):                        sigma = lambda / (2 pi) sqrt(B_pll / c (1 + 1 / (2 T c)))       [m]
* FLL (Doppler):                       sigma = 1 / (2 pi T) sqrt(4 F B_fll / c (1 + 1 / (T c)))       [Hz],
  F = 1 at high C/N0.
"""
from __future__ import annotations

import numpy as np


def cn0_dbhz(off_boresight_rad, cn0_zenith_dbhz, rolloff_db, offset_db):
    """C/N0 (dB-Hz) for the angle between line of sight and antenna boresight (rad)."""
    return cn0_zenith_dbhz + offset_db - rolloff_db * (off_boresight_rad / (np.pi / 2.0)) ** 2


def pattern_cn0_dbhz(off_boresight_rad, cn0_zenith_dbhz, pattern, offset_db):
    """C/N0 (dB-Hz) with a tabulated gain ``pattern`` ((off-boresight deg, ...), (gain dB, ...)) instead of the
    quadratic rolloff; linear in the angle, the end values beyond the table."""
    return cn0_zenith_dbhz + offset_db + np.interp(np.degrees(off_boresight_rad), pattern[0], pattern[1])


def dll_sigma_m(cn0_db, chip_length_m, b_dll_hz, spacing_chips, t_int_s):
    """Code (DLL) thermal-noise standard deviation (m)."""
    c = 10.0 ** (np.asarray(cn0_db) / 10.0)
    d = spacing_chips
    return chip_length_m * np.sqrt(b_dll_hz * d / (2.0 * c) * (1.0 + 2.0 / (t_int_s * c * (2.0 - d))))


def pll_sigma_m(cn0_db, wavelength_m, b_pll_hz, t_int_s):
    """Carrier (PLL) thermal-noise standard deviation (m)."""
    c = 10.0 ** (np.asarray(cn0_db) / 10.0)
    return wavelength_m / (2.0 * np.pi) * np.sqrt(b_pll_hz / c * (1.0 + 1.0 / (2.0 * t_int_s * c)))


def fll_sigma_hz(cn0_db, b_fll_hz, t_int_s):
    """Doppler (FLL) thermal-noise standard deviation (Hz)."""
    c = 10.0 ** (np.asarray(cn0_db) / 10.0)
    return 1.0 / (2.0 * np.pi * t_int_s) * np.sqrt(4.0 * b_fll_hz / c * (1.0 + 1.0 / (t_int_s * c)))
