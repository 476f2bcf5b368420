"""Per-system constants for orbit and clock computation.

Each system's broadcast orbit uses its own gravitational constant and Earth rotation rate (IS-GPS-200 Table
20-IV; BDS-SIS-ICD-B1I 5.2.4). The relativistic clock constant is F = -2 sqrt(mu) / c^2 (s / m^0.5).
The fit half-widths are those of the ``state()`` semantics in docs/constellation.md: GPS and QZSS +-2 h,
BDS +-1 h around toe, Galileo 4 h after toe (GLONASS +-30 min, in glonass.py).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..earth import C_LIGHT


@dataclass(frozen=True)
class System:
    code: str          # RINEX system letter
    name: str
    mu: float          # m^3/s^2
    omega_e: float     # rad/s
    fit_half_s: float  # broadcast-ephemeris validity either side of toe, s
    time_offset_s: float  # GPST - system time, s (BDT = GPST - 14 s)
    week_offset: int      # GPS week - system week

    @property
    def rel_f(self) -> float:
        """Relativistic clock constant F = -2 sqrt(mu) / c^2, s/m^0.5."""
        return -2.0 * self.mu**0.5 / C_LIGHT**2


GPS = System("G", "GPS", 3.986005e14, 7.2921151467e-5, 7200.0, 0.0, 0)
BDS = System("C", "BDS", 3.986004418e14, 7.292115e-5, 3600.0, 14.0, 1356)
# Galileo (OS SIS ICD 2.1 Table 48): GST weeks and seconds as RINEX writes them are aligned with GPS weeks and
# GPST (the broadcast GGTO, a few ns, is not applied to orbits). A record holds for 4 h after its toe (the
# latest record before t is used, see model.Records.after_toe).
GAL = System("E", "Galileo", 3.986004418e14, 7.2921151467e-5, 14400.0, 0.0, 0)
# QZSS (IS-QZSS-PNT 4.1.2): GPS constants, QZSST = GPST, 2 h fit like GPS LNAV
QZS = System("J", "QZSS", 3.986005e14, 7.2921151467e-5, 7200.0, 0.0, 0)
SYSTEMS = {"G": GPS, "C": BDS, "E": GAL, "J": QZS}  # Keplerian systems (GLONASS: see glonass.py)

# BDS GEO decision from the orbit, not the PRN: geosynchronous (semi-major axis above 40,000 km) and an
# inclination below 10 deg. BDS GEOs fly at i < 2 deg, IGSOs at about 55 deg, so any threshold in between works.
GEO_MIN_A_M = 40.0e6
GEO_MAX_INC_RAD = 10.0 * 3.141592653589793 / 180.0
