"""Broadcast orbit and clock errors: where the true satellite is, relative to where its ephemeris puts it.

The file's ``/gnss/sat_pos_ecef`` and ``/gnss/sat_clock`` stay the broadcast orbit and clock (what a receiver
computes from the navigation message); the observables are formed with the true satellite, displaced by an orbit
error in radial, along-track and cross-track axes (RAC), and the true clock, offset by a clock error.

Per satellite and ephemeris interval (the record with the nearest toe, toes every ``interval_s`` of GPS time, as
GPS's 2 h and BDS's 1 h uploads), each of the four components (R, A, C, clock) is a quadratic in the normalised time
tau = (t - toe) / (interval/2) in [-1, 1):

    e(tau) = sigma (sqrt(0.5) z0 + sqrt(0.9) z1 tau + sqrt(45/16) z2 (tau^2 - 1/3))

with z ~ N(0, 1) drawn from the stream ``gnss/ephemeris/<sat>/<interval index>``, so that the RMS over an interval is
sigma; the errors jump at each ephemeris update and are smooth in between. The RAC axes: R along the satellite's
position, C along r x v (inertial velocity), A = C x R.
"""
from __future__ import annotations

import math

import numba
import numpy as np

from .. import rng
from ..gpstime import SECONDS_PER_WEEK
from .truth_config import EphemerisErrorConfig

_SHAPE = np.array([np.sqrt(0.5), np.sqrt(0.9), np.sqrt(45.0 / 16.0)])


def rac_axes(pos, vel_inertial):
    """Radial, along-track and cross-track unit vectors (..., 3, 3) (rows R, A, C) of satellites at ``pos``
    (..., 3) m moving at ``vel_inertial`` (..., 3) m/s."""
    r = pos / np.linalg.norm(pos, axis=-1, keepdims=True)
    c = np.cross(pos, vel_inertial)
    c /= np.linalg.norm(c, axis=-1, keepdims=True)
    return np.stack([r, np.cross(c, r), c], axis=-2)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _evaluate(t_abs, live, interval, first, coef, out, rate):
    """e(tau) and de/dt into ``out``/``rate`` (M, C, 4) at columns ``live`` (L,), intervals ``interval`` (L,) s,
    coefficient rows (z0, z1, z2) ``coef`` (L, J, 3, 4) of the intervals ``first`` (L,) + 0 .. J - 1."""
    for m in range(t_abs.size):
        for i in range(live.size):
            j = math.floor(t_abs[m] / interval[i] + 0.5)
            half = 0.5 * interval[i]
            tau = (t_abs[m] - j * interval[i]) / half
            z = coef[i, np.int64(j) - first[i]]
            for k in range(4):
                out[m, live[i], k] = z[0, k] + z[1, k] * tau + z[2, k] * (tau**2 - 1.0 / 3.0)
                rate[m, live[i], k] = (z[1, k] + 2.0 * z[2, k] * tau) / half


class EphemerisErrors:
    """Orbit (RAC) and clock errors of satellites ``sat_ids`` under scenario ``seed``; ``systems`` maps a system
    letter to its :class:`EphemerisErrorConfig` (satellites of other systems get none); the sigmas of GEO and
    IGSO satellites (``orbit_type``) are multiplied by their system's ``geosync_scale``."""

    def __init__(self, seed: int, sat_ids, systems: dict[str, EphemerisErrorConfig], orbit_type=None):
        self.seed, self.sat_ids = seed, list(sat_ids)
        cfgs = [systems.get(s[0]) for s in self.sat_ids]
        self.sigma = np.array([(*c.orbit_sigma_rac_m, c.clock_sigma_m) if c else (0.0,) * 4 for c in cfgs])
        if orbit_type is not None:   # ``orbit_type`` (S,) 'MEO'/'IGSO'/'GEO': geosynchronous ones scaled
            geo = np.isin(np.asarray(orbit_type), ("GEO", "IGSO"))
            self.sigma *= np.where(geo, [c.geosync_scale if c else 1.0 for c in cfgs], 1.0)[:, None]
        self.interval = np.array([c.interval_s if c else 7200.0 for c in cfgs])
        self.departs = bool(np.any(self.sigma > 0))
        self._coef: dict[tuple[int, int], np.ndarray] = {}

    def _coefficients(self, s: int, j: int) -> np.ndarray:
        key = (s, j)
        if key not in self._coef:
            z = rng.generator(self.seed, "gnss", "ephemeris", self.sat_ids[s], str(j)).standard_normal((3, 4))
            self._coef[key] = z * _SHAPE[:, None] * self.sigma[s]
        return self._coef[key]

    def at(self, week, sow, cols):
        """Errors (M, C, 4) m [radial, along, cross, clock] and their rates (M, C, 4) m/s at GPS times
        (``week``, ``sow``) (M,) for satellite columns ``cols`` (C,). The clock error is c (dT_true - dT_broadcast)."""
        t_abs = np.asarray(week, dtype=float) * SECONDS_PER_WEEK + np.asarray(sow, dtype=float)   # (M,)
        cols = np.asarray(cols, dtype=np.int64)
        out = np.zeros((t_abs.size, cols.size, 4))
        rate = np.zeros_like(out)
        live = np.flatnonzero(np.any(self.sigma[cols] > 0, axis=1))
        if t_abs.size and live.size:
            interval = self.interval[cols[live]]
            first = np.floor(t_abs.min() / interval + 0.5).astype(np.int64)
            last = np.floor(t_abs.max() / interval + 0.5).astype(np.int64)
            # the coefficients of every interval a satellite enters during the call (one or two for a run's block)
            span = int((last - first).max()) + 1
            coef = np.zeros((live.size, span, 3, 4))
            for i, s in enumerate(cols[live]):
                for o in range(int(last[i] - first[i]) + 1):
                    coef[i, o] = self._coefficients(int(s), int(first[i]) + o)
            _evaluate(np.ascontiguousarray(t_abs), live, interval, first, coef, out, rate)
        # keep the cache small: intervals behind the last epoch's are never asked for again (epochs in order)
        if len(self._coef) > 4 * len(self.sat_ids) and t_abs.size:
            last = np.floor(t_abs[-1] / self.interval + 0.5)
            self._coef = {k: v for k, v in self._coef.items() if k[1] >= last[k[0]]}
        return out, rate
