"""GNSS signals: exact carrier frequencies, chip rates, RINEX 3.04 observation codes and group-delay scaling.

Frequencies are multiples of the 10.23 MHz fundamental (IS-GPS-200 3.3.1.1, IS-GPS-705, BDS-SIS-ICD B1I 3.0,
B3I 1.0, B1C 1.0, B2a 1.0). ``tgd_factor`` maps the broadcast group delay to this signal's code delay in seconds:
GPS (IS-GPS-200 20.3.3.3.3.2) delays L1 by T_GD and L2 by gamma*T_GD with gamma = (f_L1/f_L2)^2; BDS D1/D2
(B1I ICD 5.2.4.10) gives TGD1 for B1I and TGD2 for B2I relative to B3I (delay 0).
"""
from __future__ import annotations

from dataclasses import dataclass

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
    tgd: str              # which broadcast group delay applies: "tgd" (GPS T_GD), "tgd1", "tgd2", "none"
    tgd_scale: float      # multiplier on that group delay
    cn0_offset_db: float  # nominal C/N0 relative to GPS L1 C/A (received power and code type)

    @property
    def wavelength_m(self) -> float:
        return C_LIGHT / self.freq_hz

    @property
    def chip_length_m(self) -> float:
        return C_LIGHT / self.chip_rate_hz

    def rinex_codes(self) -> tuple[str, str, str, str]:
        """RINEX 3 observation types (code, phase, Doppler, signal strength), e.g. C1C L1C D1C S1C."""
        s = self.rinex_band + self.rinex_attr
        return "C" + s, "L" + s, "D" + s, "S" + s


_GAMMA_L2 = (154.0 / 120.0) ** 2
_GAMMA_L5 = (154.0 / 115.0) ** 2

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
)}


def get(name: str) -> Signal:
    """The :class:`Signal` called ``name``; KeyError lists the known names."""
    try:
        return SIGNALS[name]
    except KeyError:
        raise KeyError(f"unknown signal {name!r} (known: {', '.join(SIGNALS)})") from None
