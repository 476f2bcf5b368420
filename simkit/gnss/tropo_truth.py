"""The truth troposphere: other zenith delays and another mapping function than the receiver's model.

The receiver's model (:func:`simkit.gnss.atmosphere.troposphere`) is the Saastamoinen zenith delay of a standard
atmosphere mapped with 1/sin(el) for both parts. The truth is

    T = (ZHD + dZHD) m_h(el) + max(ZWD + dZWD + w(t), 0) m_w(el)

with ZHD, ZWD the same Saastamoinen zenith delays, dZHD and dZWD constant offsets drawn once per run (weather differs
from the standard atmosphere), w(t) a zenith-wet random walk (``tropo_zwd_random_walk_m_per_sqrt_h``) sampled every
600 s and joined by a C1 cubic Hermite curve (so the delay has a rate), and m_h, m_w the Niell (1996) mapping functions
(``tropo_mapping = "niell"``) or 1/sin(el) (``"model"``). The draws come from the stream ``gnss/truth/troposphere``.
Rates are central differences over +-``h`` s along the receiver's height and the satellite's elevation.
"""
from __future__ import annotations

import math

import numba
import numpy as np
from scipy.interpolate import CubicHermiteSpline

from .. import gpstime, rng
from .atmosphere import saastamoinen_zenith, troposphere

KNOT_S = 600.0

# Niell (1996) mapping-function coefficients at latitudes 15, 30, 45, 60, 75 deg: a, b, c rows.
_NMF_LAT = np.radians([15.0, 30.0, 45.0, 60.0, 75.0])
_NMF_HYD_AVG = np.array([[1.2769934e-3, 1.2683230e-3, 1.2465397e-3, 1.2196049e-3, 1.2045996e-3],
                         [2.9153695e-3, 2.9152299e-3, 2.9288445e-3, 2.9022565e-3, 2.9024912e-3],
                         [62.610505e-3, 62.837393e-3, 63.721774e-3, 63.824265e-3, 64.258455e-3]])
_NMF_HYD_AMP = np.array([[0.0, 1.2709626e-5, 2.6523662e-5, 3.4000452e-5, 4.1202191e-5],
                         [0.0, 2.1414979e-5, 3.0160779e-5, 7.2562722e-5, 11.723375e-5],
                         [0.0, 9.0128400e-5, 4.3497037e-5, 84.795348e-5, 170.37206e-5]])
_NMF_WET = np.array([[5.8021897e-4, 5.6794847e-4, 5.8118019e-4, 5.9727542e-4, 6.1641693e-4],
                     [1.4275268e-3, 1.5138625e-3, 1.4572752e-3, 1.5007428e-3, 1.7599082e-3],
                     [4.3472961e-2, 4.6729510e-2, 4.3908931e-2, 4.4626982e-2, 5.4736038e-2]])
_NMF_HT = (2.53e-5, 5.49e-3, 1.14e-3)


def _marini(s, a, b, c):
    """Marini's continued fraction in ``s`` = sin(el), normalised to 1 at the zenith (Niell's form)."""
    return (1.0 + a / (1.0 + b / (1.0 + c))) / (s + a / (s + b / (s + c)))


_marini_scalar = numba.njit(cache=True, inline="always", error_model="numpy")(_marini)


def _niell_coefficients(lat, doy):
    """Hydrostatic (a, b, c) and wet (a, b, c) of the Niell mapping at latitude ``lat`` rad and day of year
    ``doy`` (broadcast together): two lists of three arrays."""
    alat = np.clip(np.abs(lat), _NMF_LAT[0], _NMF_LAT[-1])
    season = np.cos(2.0 * np.pi * ((doy - 28.0) / 365.25 + np.where(lat < 0.0, 0.5, 0.0)))

    def coef(table, i):
        return np.interp(alat, _NMF_LAT, table[i])

    return ([coef(_NMF_HYD_AVG, i) - coef(_NMF_HYD_AMP, i) * season for i in range(3)],
            [coef(_NMF_WET, i) for i in range(3)])


def niell_mapping(lat, h, el, doy):
    """Niell hydrostatic and wet mapping functions (m_h, m_w) at latitude ``lat`` rad, ellipsoidal height ``h`` m,
    elevation ``el`` rad, day of year ``doy`` (UTC, fractional); broadcast together."""
    hyd, wet = _niell_coefficients(lat, doy)
    s = np.sin(el)
    m_h = _marini(s, *hyd) + (1.0 / s - _marini(s, *_NMF_HT)) * h / 1e3
    m_w = _marini(s, *wet)
    return m_h, m_w


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _slants(niell, el, el_rate, steps, hyd, wet, height, zhd, zwd, model_zenith, out):
    """Truth slant delays at the time steps and the receiver's model delay, per receiver r and line of sight c:
    ``out[j]`` (J, R, C) at elevation el + steps[j] el_rate (steps[0] = 0: el itself), ``out[J]`` the model
    (zenith / sin el)."""
    ht_a, ht_b, ht_c = _NMF_HT
    n_j = steps.size
    for r in range(el.shape[0]):
        for c in range(el.shape[1]):
            s0 = math.sin(el[r, c])
            for j in range(n_j):
                s = s0 if j == 0 else math.sin(el[r, c] + steps[j] * el_rate[r, c])
                if niell:
                    m_h = (_marini_scalar(s, hyd[j, 0, r], hyd[j, 1, r], hyd[j, 2, r])
                           + (1.0 / s - _marini_scalar(s, ht_a, ht_b, ht_c)) * height[j, r] / 1e3)
                    m_w = _marini_scalar(s, wet[0, r], wet[1, r], wet[2, r])
                else:
                    m_h = m_w = 1.0 / s
                out[j, r, c] = zhd[j, r] * m_h + zwd[j, r] * m_w
            out[n_j, r, c] = model_zenith[r] / s0


class TruthTroposphere:
    """Truth slant delay for a run starting at GPS (``start_week``, ``start_sow``) lasting ``duration_s``."""

    def __init__(self, seed: int, start_week: int, start_sow: float, duration_s: float, mapping: str,
                 zhd_sigma_m: float, zwd_sigma_m: float, zwd_rw_m_per_sqrt_h: float):
        gen = rng.generator(seed, "gnss", "truth", "troposphere")
        off = gen.standard_normal(2)
        self.dzhd, self.dzwd = off[0] * zhd_sigma_m, off[1] * zwd_sigma_m
        knots = np.arange(-1, int(np.ceil(duration_s / KNOT_S)) + 3) * KNOT_S
        steps = gen.standard_normal(knots.size) * zwd_rw_m_per_sqrt_h * np.sqrt(KNOT_S / 3600.0)
        walk = np.cumsum(steps)
        walk -= walk[1]  # w = 0 at t = 0 (knot 1): the offset dZWD is the start value
        self.walk = CubicHermiteSpline(knots, walk, np.gradient(walk, knots))
        self.mapping = mapping
        self.departs = mapping != "model" or zhd_sigma_m > 0 or zwd_sigma_m > 0 or zwd_rw_m_per_sqrt_h > 0
        utc = gpstime.gps_to_utc(start_week, start_sow)
        self.doy = utc.timetuple().tm_yday + (utc.hour * 3600 + utc.minute * 60 + utc.second) / 86400.0  # RTKLIB time2doy: 1.0 at Jan 1 0h

    def delay(self, lat, h, el, t):
        """Truth slant delay (m) at latitude ``lat`` rad, height ``h`` m, elevation ``el`` rad, ``t`` s since the
        start (broadcast together)."""
        zh, zw = saastamoinen_zenith(lat, h)
        zwd = np.maximum(zw + self.dzwd + self.walk(t), 0.0)
        if self.mapping == "niell":
            m_h, m_w = niell_mapping(lat, h, el, self.doy + t / 86400.0)
        else:
            m_h = m_w = 1.0 / np.sin(el)
        return (zh + self.dzhd) * m_h + zwd * m_w

    def slant(self, lat, h, el, h_rate, el_rate, t, dt: float = 0.05):
        """(truth, truth rate, model) m, m/s, m: the truth and its rate for a receiver at latitude ``lat`` rad and
        height ``h`` m climbing at ``h_rate`` m/s, a satellite at elevation ``el`` rad rising at ``el_rate``
        rad/s, ``t`` s since the start (broadcast together), and the receiver's model delay
        (:func:`simkit.gnss.atmosphere.troposphere`). The formulas of :meth:`delay` in one compiled pass over the
        lines of sight; receiver terms are taken once per receiver when ``lat``, ``h``, ``h_rate`` and ``t`` are
        constant along the last axis (receivers (M, A, 1), lines of sight (M, A, C))."""
        shape = np.broadcast_shapes(*(np.shape(x) for x in (lat, h, el, h_rate, el_rate, t)))
        full = shape or (1,)
        try:
            rows = full[:-1] + (1,)
            lat, h, h_rate, t = (np.broadcast_to(x, rows).reshape(-1) for x in (lat, h, h_rate, t))
            cols = full[-1]
        except ValueError:  # receiver terms that vary along the last axis: one row per element
            lat, h, h_rate, t = (np.broadcast_to(x, full).reshape(-1) for x in (lat, h, h_rate, t))
            cols = 1
        el, el_rate = (np.ascontiguousarray(np.broadcast_to(x, full), dtype=float).reshape(-1, cols)
                       for x in (el, el_rate))
        height = np.stack([h, h + dt * h_rate, h - dt * h_rate])                        # (J, R)
        when = np.stack([t, t + dt, t - dt])                                            # (J, R)
        zh, zw = saastamoinen_zenith(lat, height)
        zwd = np.maximum(zw + self.dzwd + self.walk(when), 0.0)
        hyd, wet = _niell_coefficients(lat, self.doy + when / 86400.0)
        hyd = np.stack(np.broadcast_arrays(*hyd, height)[:3], axis=1)                   # (J, 3, R)
        wet = np.stack([np.broadcast_to(w, lat.shape) for w in wet])                      # (3, R)
        model = np.add(*saastamoinen_zenith(lat, h))
        out = np.empty((4,) + el.shape)
        _slants(self.mapping == "niell", el, el_rate, np.array([0.0, dt, -dt]), np.ascontiguousarray(hyd),
                np.ascontiguousarray(wet), np.ascontiguousarray(height), np.ascontiguousarray(zh + self.dzhd),
                np.ascontiguousarray(zwd), np.ascontiguousarray(model), out)
        out = out.reshape((4,) + shape)
        return out[0], (out[1] - out[2]) / (2.0 * dt), out[3]
