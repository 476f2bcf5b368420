"""The truth ionosphere's per-line-of-sight work at its three time steps, in one compiled pass.

:meth:`simkit.gnss.iono_truth.TruthIonosphere.delay` needs, for every epoch, antenna and satellite, at t - h, t and
t + h (receiver and satellite moved along their rates): the broadcast Klobuchar delay (GPS or BDS variant,
:mod:`simkit.gnss.atmosphere`) and the Earth-fixed point where the line of sight pierces the random field's shell
(:func:`simkit.gnss.iono_truth.pierce_point`). As array expressions that is some forty (M, A, C) temporaries per
step; here each line of sight is carried through the same formulas in scalars, with the sines and cosines of the
receiver's latitude and longitude taken once per antenna and step, and those of the shells' Earth-centred angle and
of the pierce point by the angle-sum formulas (square roots instead of arcsines, sines and cosines). The results
equal the array expressions to rounding: 1e-12 m in the delays, 1e-6 m on the 6.7e6 m shell
(tests/test_gnss_iono_steps.py).
"""
from __future__ import annotations

import math

import numba
import numpy as np

from ..earth import C_LIGHT
from ..gpstime import BDT_MINUS_GPST

_HALF_PI = 0.5 * math.pi
_POLE_LAT = math.radians(70.0)
_BDS_RATIO = 6378.0e3 / (6378.0e3 + 375.0e3)   # the BDS model's shell: R = 6378 km, h = 375 km


@numba.njit(cache=True, inline="always", error_model="numpy")
def _clip(x, lo, hi):
    """np.clip for a scalar (NaN stays NaN)."""
    return lo if x < lo else (hi if x > hi else x)


@numba.njit(cache=True, inline="always", error_model="numpy")
def _poly(c, x):
    return c[0] + x * (c[1] + x * (c[2] + x * c[3]))


@numba.njit(cache=True, inline="always", error_model="numpy")
def _klobuchar_gps(alpha, beta, lat, lon, sin_az, cos_az, el, tow_s):
    """:func:`simkit.gnss.atmosphere.klobuchar_gps` for one line of sight (m on L1)."""
    e = el / math.pi
    psi = 0.0137 / (e + 0.11) - 0.022
    phi_i = _clip(lat / math.pi + psi * cos_az, -0.416, 0.416)
    lam_i = lon / math.pi + psi * sin_az / math.cos(phi_i * math.pi)
    phi_m = phi_i + 0.064 * math.cos((lam_i - 1.617) * math.pi)
    t = (4.32e4 * lam_i + tow_s) % 86400.0
    f = 1.0 + 16.0 * (0.53 - e) ** 3
    amp = _poly(alpha, phi_m)
    amp = 0.0 if amp < 0.0 else amp
    per = _poly(beta, phi_m)
    per = 72000.0 if per < 72000.0 else per
    x = 2.0 * math.pi * (t - 50400.0) / per
    night = 5e-9
    if abs(x) < 1.57:
        return C_LIGHT * f * (night + amp * (1.0 - x**2 / 2.0 + x**4 / 24.0))
    return C_LIGHT * f * night


@numba.njit(cache=True, inline="always", error_model="numpy")
def _earth_angle(ratio, sin_el, cos_el):
    """(sin psi, cos psi, sqrt(1 - k^2)) of the Earth-centred angle psi = pi/2 - el - asin(k), k = ``ratio`` cos el,
    between the receiver and the pierce point of a shell (``ratio`` = R / (R + h)), by the angle-sum formulas."""
    k = ratio * cos_el
    q = math.sqrt(1.0 - k * k)
    return cos_el * q - sin_el * k, sin_el * q + cos_el * k, q


@numba.njit(cache=True, inline="always", error_model="numpy")
def _klobuchar_bds(alpha, beta, sin_lat, cos_lat, lon, sin_az, cos_az, sin_el, cos_el, bdt_tow_s):
    """:func:`simkit.gnss.atmosphere.klobuchar_bds` for one line of sight (m on B1I)."""
    sin_psi, cos_psi, q = _earth_angle(_BDS_RATIO, sin_el, cos_el)
    sin_phi = sin_lat * cos_psi + cos_lat * sin_psi * cos_az
    phi_m = math.asin(sin_phi)
    lam_m = lon + math.asin(_clip(sin_psi * sin_az / math.sqrt(1.0 - sin_phi * sin_phi), -1.0, 1.0))
    t = (43200.0 * lam_m / math.pi + bdt_tow_s) % 86400.0
    x = abs(phi_m / math.pi)
    a2 = _poly(alpha, x)
    a2 = 0.0 if a2 < 0.0 else a2
    a4 = _clip(_poly(beta, x), 72000.0, 172800.0)
    iz = 5e-9 + a2 * math.cos(2.0 * math.pi * (t - 50400.0) / a4) if abs(t - 50400.0) < a4 / 4.0 else 5e-9
    return C_LIGHT * iz / q


@numba.njit(cache=True, inline="always", error_model="numpy")
def _pierce(lat, sin_lat, cos_lat, sin_lon, cos_lon, sin_az, cos_az, sin_el, cos_el, ratio, r):
    """:func:`simkit.gnss.iono_truth.pierce_point` for one line of sight, as the Earth-fixed point (x, y, z) m on
    the shell of radius ``r``: the sines and cosines of the pierce point's latitude and longitude come from those
    of the receiver and the angles by the angle-sum formulas."""
    sin_psi, cos_psi, _ = _earth_angle(ratio, sin_el, cos_el)
    sin_p = sin_lat * cos_psi + cos_lat * sin_psi * cos_az                # sin of the pierce point's latitude
    cos_p = math.sqrt(1.0 - sin_p * sin_p)
    tanap = sin_psi / cos_psi
    over_pole = ((lat > _POLE_LAT) and (tanap * cos_az > math.tan(_HALF_PI - lat))) or \
                ((lat < -_POLE_LAT) and (-tanap * cos_az > math.tan(_HALF_PI + lat)))
    sin_d = _clip(sin_psi * sin_az / cos_p, -1.0, 1.0)                    # the longitude step d = asin(sin_d)
    cos_d = math.sqrt(1.0 - sin_d * sin_d)
    if over_pole:  # lon + pi - d
        cos_l, sin_l = -(cos_lon * cos_d + sin_lon * sin_d), -(sin_lon * cos_d - cos_lon * sin_d)
    else:          # lon + d
        cos_l, sin_l = cos_lon * cos_d - sin_lon * sin_d, sin_lon * cos_d + cos_lon * sin_d
    return r * cos_p * cos_l, r * cos_p * sin_l, r * sin_p


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _steps(bds, alpha, beta, lat, lon, lat_rate, lon_rate, az, el, az_rate, el_rate, sow, steps, shell_ratio,
           shell_r, klob, points):
    for m in range(az.shape[0]):
        for a in range(az.shape[1]):
            for j in range(steps.shape[0]):
                s = steps[j]
                la, lo, tow = lat[m, a] + s * lat_rate[m, a], lon[m, a] + s * lon_rate[m, a], sow[m] + s
                sin_la, cos_la, sin_lo, cos_lo = math.sin(la), math.cos(la), math.sin(lo), math.cos(lo)
                for c in range(az.shape[2]):
                    az_s, el_s = az[m, a, c] + s * az_rate[m, a, c], el[m, a, c] + s * el_rate[m, a, c]
                    sin_az, cos_az, sin_el, cos_el = math.sin(az_s), math.cos(az_s), math.sin(el_s), math.cos(el_s)
                    if bds:
                        klob[m, a, j, c] = _klobuchar_bds(alpha, beta, sin_la, cos_la, lo, sin_az, cos_az, sin_el,
                                                          cos_el, tow + BDT_MINUS_GPST)
                    else:
                        klob[m, a, j, c] = _klobuchar_gps(alpha, beta, la, lo, sin_az, cos_az, el_s, tow)
                    if points.shape[0]:
                        points[m, a, j, c, 0], points[m, a, j, c, 1], points[m, a, j, c, 2] = _pierce(
                            la, sin_la, cos_la, sin_lo, cos_lo, sin_az, cos_az, sin_el, cos_el, shell_ratio, shell_r)


def klobuchar_and_pierce_points(system: str, alpha, beta, lat, lon, lat_rate, lon_rate, az, el, az_rate, el_rate,
                                sow, steps, radius_m: float, height_m: float):
    """Broadcast Klobuchar delays (M, A, J, C) m (system 'G': GPS model, L1; 'C': BDS model, B1I, BDT from GPS
    time) and pierce points (M, A, J, C, 3) m, Earth-fixed, on the shell ``height_m`` above a sphere of
    ``radius_m``, at the time steps ``steps`` (J,) s: receivers at ``lat``/``lon`` (M, A) rad moving at
    ``lat_rate``/``lon_rate`` rad/s, satellites at ``az``/``el`` (M, A, C) rad moving at ``az_rate``/``el_rate``
    rad/s, GPS seconds of week ``sow`` (M,)."""
    if system not in ("G", "C"):
        raise ValueError(f"system: {system!r} has no broadcast Klobuchar model; expected 'G' or 'C'")
    f = [np.ascontiguousarray(x, dtype=float) for x in (alpha, beta, lat, lon, lat_rate, lon_rate, az, el,
                                                        az_rate, el_rate, sow, steps)]
    m, a, c = f[6].shape
    klob = np.empty((m, a, f[11].size, c))
    points = np.empty((m, a, f[11].size, c, 3))
    _steps(system == "C", *f, radius_m / (radius_m + height_m), radius_m + height_m, klob, points)
    return klob, points


def klobuchar_delays(system: str, alpha, beta, lat, lon, az, el, sow) -> np.ndarray:
    """Broadcast Klobuchar delays (M, A, C) m (system 'G': GPS model, L1; 'C': BDS model, B1I, BDT from GPS time)
    of receivers at ``lat``/``lon`` (M, A) rad seeing satellites at ``az``/``el`` (M, A, C) rad at GPS seconds of
    week ``sow`` (M,): :func:`klobuchar_and_pierce_points` at one time step, without the pierce points."""
    if system not in ("G", "C"):
        raise ValueError(f"system: {system!r} has no broadcast Klobuchar model; expected 'G' or 'C'")
    f = [np.ascontiguousarray(x, dtype=float) for x in (alpha, beta, lat, lon, az, el, sow)]
    m, a, c = f[4].shape
    zero_ma, zero_mac = np.zeros((m, a)), np.zeros((m, a, c))
    klob = np.empty((m, a, 1, c))
    _steps(system == "C", f[0], f[1], f[2], f[3], zero_ma, zero_ma, f[4], f[5], zero_mac, zero_mac, f[6],
           np.zeros(1), 1.0, 1.0, klob, np.empty((0, 0, 0, 0, 3)))
    return klob[:, :, 0]
