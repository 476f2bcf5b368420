"""Ionosphere (broadcast Klobuchar, GPS and BDS variants) and troposphere (Saastamoinen) delays.

All functions are vectorised: receiver geodetic lat/lon (rad) and height (m), azimuth/elevation (rad) and time of
day broadcast together. Delays are returned in metres.

* GPS Klobuchar: IS-GPS-200 20.3.3.5.2.5 (Figure 20-4), thin shell with the obliquity factor
  F = 1 + 16 (0.53 - E)^3 and the cosine expanded to fourth order; geomagnetic latitude of the pierce point;
  time of day in GPS time. The delay is for L1; other frequencies scale by (f_L1/f)^2.
* BDS Klobuchar: BDS-SIS-ICD-B1I 3.0 sec. 5.2.4.7: pierce point on a 375 km shell (R = 6378 km), geographic
  latitude of the pierce point, exact cosine, period clamped to [72000, 172800] s, time of day in BDT, obliquity
  1/sqrt(1 - (R cos E/(R + h))^2). The delay is for B1I; other frequencies scale by (f_B1I/f)^2.
* Saastamoinen zenith delays (Saastamoinen 1972) for the standard atmosphere at the receiver height
  (p0 = 1013.25 hPa, T0 = 288.15 K, lapse 6.5 K/km, relative humidity 50 %), mapped with 1/sin(el) for both the
  hydrostatic and wet parts, as RTKLIB's ``tropmodel`` does.

Default broadcast coefficients (used when the navigation source carries none) are the GPSA/GPSB and BDSA/BDSB
lines of the IGS/MGEX merged file BRDM00DLR_S_20261170000_01D_MN.rnx (2026-04-27).
"""
from __future__ import annotations

import numpy as np

from .. import earth
from ..earth import C_LIGHT
from ..gpstime import BDT_MINUS_GPST
from .signals import SIGNALS

DEFAULT_GPS_ALPHA = (2.2352e-08, 1.4901e-08, -1.1921e-07, -5.9605e-08)
DEFAULT_GPS_BETA = (1.2493e05, 6.5536e04, -1.9661e05, 6.5536e04)
DEFAULT_BDS_ALPHA = (3.3528e-08, 6.7055e-08, -1.0133e-06, 1.6093e-06)
DEFAULT_BDS_BETA = (1.1878e05, 3.2768e04, 7.8643e05, -7.8643e05)

F_L1 = SIGNALS["L1C"].freq_hz   # reference frequency of the GPS broadcast model
F_B1I = SIGNALS["B1I"].freq_hz  # reference frequency of the BDS broadcast model


def _poly(c, x):
    return c[0] + x * (c[1] + x * (c[2] + x * c[3]))


def klobuchar_gps(alpha, beta, lat, lon, az, el, tow_s):
    """GPS broadcast ionospheric delay on L1 (m). ``tow_s``: GPS seconds of week (or of day)."""
    e = el / np.pi  # semicircles
    psi = 0.0137 / (e + 0.11) - 0.022
    phi_i = np.clip(lat / np.pi + psi * np.cos(az), -0.416, 0.416)
    lam_i = lon / np.pi + psi * np.sin(az) / np.cos(phi_i * np.pi)
    phi_m = phi_i + 0.064 * np.cos((lam_i - 1.617) * np.pi)
    t = np.mod(4.32e4 * lam_i + tow_s, 86400.0)
    f = 1.0 + 16.0 * (0.53 - e) ** 3
    amp = np.maximum(_poly(alpha, phi_m), 0.0)
    per = np.maximum(_poly(beta, phi_m), 72000.0)
    x = 2.0 * np.pi * (t - 50400.0) / per
    night = 5e-9
    day = night + amp * (1.0 - x**2 / 2.0 + x**4 / 24.0)
    return C_LIGHT * f * np.where(np.abs(x) < 1.57, day, night)


def klobuchar_bds(alpha, beta, lat, lon, az, el, bdt_tow_s):
    """BDS broadcast ionospheric delay on B1I (m). ``bdt_tow_s``: BDT seconds of week (or of day)."""
    r, h = 6378.0e3, 375.0e3
    k = r / (r + h) * np.cos(el)
    psi = np.pi / 2.0 - el - np.arcsin(k)
    phi_m = np.arcsin(np.sin(lat) * np.cos(psi) + np.cos(lat) * np.sin(psi) * np.cos(az))
    lam_m = lon + np.arcsin(np.clip(np.sin(psi) * np.sin(az) / np.cos(phi_m), -1.0, 1.0))
    t = np.mod(43200.0 * lam_m / np.pi + bdt_tow_s, 86400.0)
    x = phi_m / np.pi  # semicircles
    a2 = np.maximum(_poly(alpha, np.abs(x)), 0.0)
    a4 = np.clip(_poly(beta, np.abs(x)), 72000.0, 172800.0)
    iz = np.where(np.abs(t - 50400.0) < a4 / 4.0, 5e-9 + a2 * np.cos(2.0 * np.pi * (t - 50400.0) / a4), 5e-9)
    return C_LIGHT * iz / np.sqrt(1.0 - k**2)


def saastamoinen_zenith(lat, h):
    """(hydrostatic, wet) zenith delays (m) of the standard atmosphere at latitude ``lat`` rad, height ``h`` m."""
    h = np.clip(h, 0.0, 30000.0)  # above ~30 km the standard atmosphere leaves a negligible delay
    pres = 1013.25 * (1.0 - 2.2557e-5 * h) ** 5.2568
    temp = 15.0 - 6.5e-3 * h + 273.16
    e_wv = 0.5 * 6.108 * np.exp((17.15 * temp - 4684.0) / (temp - 38.45))
    zh = 0.0022768 * pres / (1.0 - 0.00266 * np.cos(2.0 * lat) - 0.00028 * h / 1e3)
    zw = 0.002277 * (1255.0 / temp + 0.05) * e_wv
    return zh, zw


def troposphere(lat, h, el):
    """Slant tropospheric delay (m): Saastamoinen zenith delays mapped with 1/sin(el)."""
    zh, zw = saastamoinen_zenith(lat, h)
    return (zh + zw) / np.sin(el)


def troposphere_rate(lat, h, el, h_rate, el_rate, dh: float = 1.0):
    """Rate (m/s) of :func:`troposphere` for a receiver climbing at ``h_rate`` m/s and a satellite rising at
    ``el_rate`` rad/s: dT/dh h' / sin(el) - T_z cos(el) / sin(el)^2 el' (dT/dh by a central difference over
    +-``dh`` m: the zenith delay is smooth in height, the error is below 1e-9 m/m). The latitude term
    (< 1e-5 m/s at 300 m/s) is left out."""
    zh, zw = saastamoinen_zenith(lat, h)
    up, down = saastamoinen_zenith(lat, h + dh), saastamoinen_zenith(lat, h - dh)
    dz_dh = (up[0] + up[1] - down[0] - down[1]) / (2.0 * dh)
    s = np.sin(el)
    return dz_dh * h_rate / s - (zh + zw) * np.cos(el) / s**2 * el_rate


def broadcast_ionosphere(system: str, alpha, beta, lat, lon, az, el, gps_tow):
    """Broadcast Klobuchar delay (m) of ``system`` ('G': GPS model on L1; 'C': BDS model on B1I, BDT from GPS
    time) at receiver ``lat``/``lon`` rad, satellite ``az``/``el`` rad, GPS seconds of week ``gps_tow``."""
    if system == "G":
        return klobuchar_gps(alpha, beta, lat, lon, az, el, gps_tow)
    if system == "C":
        return klobuchar_bds(alpha, beta, lat, lon, az, el, gps_tow + BDT_MINUS_GPST)
    raise ValueError(f"system: {system!r} has no broadcast Klobuchar model; expected 'G' or 'C'")


def model_system(system: str) -> str:
    """Which broadcast Klobuchar model the delays of ``system`` come from: 'C' (BDS model) for BDS, else 'G'.

    Galileo's NeQuick G is not implemented: Galileo, QZSS and GLONASS take the GPS model and coefficients,
    scaled by frequency, so every system sees the same ionosphere along a line of sight."""
    return "C" if system == "C" else "G"


def reference_frequency(system: str) -> float:
    """Frequency (Hz) the broadcast model used for ``system`` refers to: B1I for 'C', L1 for the others."""
    return F_B1I if system == "C" else F_L1


def ionosphere(system: str, alpha, beta, lla, vel_enu, az, el, az_rate, el_rate, gps_tow, h: float = 0.05):
    """Broadcast ionospheric delay (m, at the system's reference frequency: L1 for 'G', B1I for 'C') and its rate
    (m/s) for receivers at ``lla`` (..., 3) moving at ``vel_enu`` (..., 3) m/s, satellites at ``az``/``el`` rad
    moving at ``az_rate``/``el_rate`` rad/s, GPS time of week ``gps_tow`` s (BDS converts to BDT).

    The rate is a central difference over +-``h`` s along both motions (receiver latitude/longitude rates
    from the radii of curvature, satellite angles linearly): the model's curvature leaves < 1e-6 m/s.
    """
    lat, lon, hgt = lla[..., 0], lla[..., 1], lla[..., 2]
    rm, rn = earth.radii(lat)
    lat_rate = vel_enu[..., 1] / (rm + hgt)
    lon_rate = vel_enu[..., 0] / ((rn + hgt) * np.cos(lat))

    def at(s):
        return broadcast_ionosphere(system, alpha, beta, (lat + s * lat_rate)[..., None],
                                    (lon + s * lon_rate)[..., None], az + s * az_rate, el + s * el_rate, gps_tow + s)

    return at(0.0), (at(h) - at(-h)) / (2.0 * h)
