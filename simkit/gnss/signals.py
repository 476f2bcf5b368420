"""GNSS signals: exact carrier frequencies, chip rates, RINEX 3.04 observation codes and group-delay scaling.

This table is the one source of the mapping between simkit signal names and RINEX 3.04 observation codes
(:func:`from_rinex` reads it backwards).

Frequencies are multiples of the 10.23 MHz fundamental (IS-GPS-200 3.3.1.1, IS-GPS-705, BDS-SIS-ICD B1I 3.0,
B3I 1.0, B1C 1.0, B2a 1.0; Galileo OS SIS ICD 2.1 Table 2; IS-QZSS-PNT 5.1 Table 3.1.2-1). GLONASS FDMA signals
(ICD 2008 3.3.1.4) have one frequency per satellite, ``freq_hz + k * fdma_step_hz`` for the satellite's channel
k (-7..13): G1 = 1602 + 0.5625 k MHz, G2 = 1246 + 0.4375 k MHz (:meth:`Signal.frequency_for`).
``tgd``/``tgd_scale`` map a broadcast group delay to this signal's code delay in seconds: GPS (IS-GPS-200
20.3.3.3.3.2) delays L1 by T_GD and L2 by gamma*T_GD with gamma = (f_L1/f_L2)^2; BDS D1/D2 (B1I ICD 5.2.4.10) gives
TGD1 for B1I and TGD2 for B2I relative to B3I (delay 0). Galileo (OS SIS ICD 5.1.5): the I/NAV clock refers to
the E1/E5b ionosphere-free combination, so E1 is delayed by BGD(E1,E5b) and E5b by (f_E1/f_E5b)^2 BGD(E1,E5b);
E5a takes (f_E1/f_E5a)^2 BGD(E1,E5a), exact for the F/NAV clock and an approximation with the I/NAV clock
(they differ by the broadcast clocks' difference, a few 0.1 ns); E6 has no open broadcast group delay and
takes (f_E1/f_E6)^2 BGD(E1,E5b) (first-order dispersive scaling, documented approximation). QZSS LNAV carries
T_GD like GPS; L2C and L5 scale it like GPS L2 and L5 (their ISCs are CNAV-only). GLONASS broadcasts no group
delay for G1/G2 C/A (tau_n refers to G1; the G1-G2 difference of the 3.05 records is not applied).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..earth import C_LIGHT

F0 = 10.23e6  # fundamental frequency, Hz


@dataclass(frozen=True)
class Signal:
    name: str             # simkit / RINEX-like name: "L1C", "B1I", ...
    system: str           # "G" (GPS) or "C" (BDS)
    freq_hz: float        # carrier frequency
    chip_rate_hz: float   # ranging-code chip rate (primary code)
    rinex_band: str       # RINEX 3.04 band digit
    rinex_attr: str       # RINEX 3.04 tracking-mode attribute
    tgd: str              # which broadcast group delay applies: "tgd" (GPS/QZSS T_GD), "tgd1", "tgd2",
    #                       "bgd_e5a", "bgd_e5b" (Galileo), "none"
    tgd_scale: float      # multiplier on that group delay
    cn0_offset_db: float  # nominal C/N0 relative to GPS L1 C/A (received power and code type)
    fdma_step_hz: float = 0.0  # GLONASS FDMA: frequency step per channel number k (0: CDMA)

    @property
    def wavelength_m(self) -> float:
        """Wavelength at ``freq_hz`` (for an FDMA signal: of channel 0; see :meth:`frequency_for`)."""
        return C_LIGHT / self.freq_hz

    @property
    def is_fdma(self) -> bool:
        return self.fdma_step_hz != 0.0

    def frequency_for(self, channel):
        """Carrier frequency (Hz) for FDMA channel number(s) ``channel`` (ignored for a CDMA signal)."""
        return self.freq_hz + self.fdma_step_hz * np.asarray(channel, dtype=float)

    @property
    def chip_length_m(self) -> float:
        return C_LIGHT / self.chip_rate_hz

    def rinex_codes(self) -> tuple[str, str, str, str]:
        """RINEX 3 observation types (code, phase, Doppler, signal strength), e.g. C1C L1C D1C S1C."""
        s = self.rinex_band + self.rinex_attr
        return "C" + s, "L" + s, "D" + s, "S" + s


_GAMMA_L2 = (154.0 / 120.0) ** 2
_GAMMA_L5 = (154.0 / 115.0) ** 2
_GAMMA_E5B = (154.0 / 118.0) ** 2
_GAMMA_E6 = (154.0 / 125.0) ** 2

SIGNALS: dict[str, Signal] = {s.name: s for s in (
    # GPS: L1 C/A; L2 P(Y) semi-codeless ("W"); L5 pilot (Q)
    Signal("L1C", "G", 154 * F0, 1.023e6, "1", "C", "tgd", 1.0, 0.0),
    Signal("L2W", "G", 120 * F0, 10.23e6, "2", "W", "tgd", _GAMMA_L2, -6.0),
    # L5: LNAV has no ISC_L5; the T_GD is scaled like L2 (first-order dispersive): documented approximation
    Signal("L5Q", "G", 115 * F0, 10.23e6, "5", "Q", "tgd", _GAMMA_L5, 3.0),
    # BDS: B1I (RINEX band 2, attr I), B3I (band 6), B1C pilot (band 1, P), B2a pilot (band 5, P)
    Signal("B1I", "C", 152.6 * F0, 2.046e6, "2", "I", "tgd1", 1.0, 0.0),
    Signal("B3I", "C", 124 * F0, 10.23e6, "6", "I", "none", 0.0, 2.0),
    # B1C and B2a: D1/D2 carry no TGD_B1Cp / TGD_B2ap; TGD1 (1561 MHz) and TGD2 (B2I, 1207 MHz) are used
    Signal("B1C", "C", 154 * F0, 1.023e6, "1", "P", "tgd1", 1.0, 1.0),
    Signal("B2a", "C", 115 * F0, 10.23e6, "5", "P", "tgd2", 1.0, 3.0),
    # Galileo: E1 pilot (C), E5a pilot (Q), E5b pilot (Q, RINEX band 7), E6 pilot (C)
    Signal("E1C", "E", 154 * F0, 1.023e6, "1", "C", "bgd_e5b", 1.0, 0.0),
    Signal("E5aQ", "E", 115 * F0, 10.23e6, "5", "Q", "bgd_e5a", _GAMMA_L5, 3.0),
    Signal("E5bQ", "E", 118 * F0, 10.23e6, "7", "Q", "bgd_e5b", _GAMMA_E5B, 3.0),
    Signal("E6C", "E", 125 * F0, 5.115e6, "6", "C", "bgd_e5b", _GAMMA_E6, 2.0),
    # GLONASS: G1 and G2 C/A, FDMA (frequency of channel k = freq_hz + k * step)
    Signal("G1C", "R", 1602.0e6, 0.511e6, "1", "C", "none", 0.0, -1.0, 0.5625e6),
    Signal("G2C", "R", 1246.0e6, 0.511e6, "2", "C", "none", 0.0, -3.0, 0.4375e6),
    # QZSS: L1 C/A, L2C pilot (L), L5 pilot (Q); named J... because GPS owns L1C/L5Q
    Signal("J1C", "J", 154 * F0, 1.023e6, "1", "C", "tgd", 1.0, 0.0),
    Signal("J2L", "J", 120 * F0, 10.23e6 / 20.0, "2", "L", "tgd", _GAMMA_L2, -3.0),
    Signal("J5Q", "J", 115 * F0, 10.23e6, "5", "Q", "tgd", _GAMMA_L5, 3.0),
)}
SYSTEM_SIGNALS = {sys: tuple(n for n, g in SIGNALS.items() if g.system == sys) for sys in "GCEJR"}


def get(name: str) -> Signal:
    """The :class:`Signal` called ``name``; KeyError lists the known names."""
    try:
        return SIGNALS[name]
    except KeyError:
        raise KeyError(f"unknown signal {name!r} (known: {', '.join(SIGNALS)})") from None


def from_rinex(system: str, code: str) -> Signal | None:
    """The signal whose RINEX 3.04 observation code (``"C1C"``, ``"L5Q"``, ... or just band + attribute
    ``"1C"``) belongs to ``system`` ('G', 'C', 'E', 'J', 'R'); None when simkit does not simulate it."""
    key = code[-2:]
    return next((g for g in SIGNALS.values() if g.system == system and g.rinex_band + g.rinex_attr == key), None)
