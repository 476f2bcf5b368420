"""GLONASS broadcast ephemerides: state vectors integrated with the PZ-90 force model.

A GLONASS record gives, at its reference time tb, the satellite's position, velocity and lunisolar acceleration
in PZ-90 (Earth-fixed; taken as WGS-84 here: < 1 m apart since PZ-90.11) and the clock terms -tau_n, gamma_n.
The orbit between records is obtained by integrating the equations of motion of the GLONASS ICD (ed. 5.1, 2008,
A.3.1.2) in the rotating frame: central term, J2 zonal term, centrifugal and Coriolis terms, plus the broadcast
acceleration held constant. The integrator is the classical fourth-order Runge-Kutta with a fixed 60 s step
(the last step shortened to land on the requested time), the same scheme and step as RTKLIB's ``geph2pos``,
so both follow the same discrete trajectory. The step is not what limits the orbit: a 1 s step moves the result
by at most 0.7 mm at 15 min and 1.3 mm at 30 min from tb (BRDM 2026, every 97th record; docs/systems.md), far
below the broadcast orbit's own error (metres).

Clock (ICD 3.3.3): dT = -tau_n + gamma_n (t - tb), in seconds, without group delays; its rate is gamma_n.
Times: the record epoch is UTC(SU) (RINEX writes it in UTC, not GLONASST = UTC(SU) + 3 h); it is turned into GPS
time with the leap seconds of skyfield's table at that instant. A record is used within +-:data:`FIT_HALF_S`
of tb (RTKLIB's limit; records are broadcast every 30 min), and the nearest healthy record is chosen.
"""
from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from ..earth import OMEGA_E  # PZ-90's Earth rotation rate, 7.292115e-5 rad/s, is WGS-84's
from .model import Constellation

MU = 3.9860044e14        # m^3/s^2, PZ-90 (GLONASS ICD 2008, Table 3.2)
J2 = 1.0826257e-3        # second zonal harmonic of the geopotential, PZ-90
RE = 6378136.0           # m, semi-major axis of PZ-90
STEP_S = 60.0            # Runge-Kutta step, s
FIT_HALF_S = 1800.0      # record validity either side of tb, s
FREQ_CHANNELS = range(-7, 14)  # valid FDMA channel numbers k (G1 = 1602 + 0.5625 k MHz)

# columns of a record table: tb (GPS s since the reference week), state (m, m/s), acceleration (m/s^2), clock
STATE_COLS = slice(1, 7)
ACC_COLS = slice(7, 10)
TB, TAUN, GAMN = 0, 10, 11
N_COLS = 12


@numba.njit(cache=True, inline="always")
def _derivative(x, acc, out):
    """Time derivative of the state x = (r, v) in the rotating PZ-90 frame (ICD A.3.1.2)."""
    r2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2]
    r = np.sqrt(r2)
    r3 = r2 * r
    j2_term = 1.5 * J2 * MU * RE * RE / (r3 * r2)  # 3/2 J2 mu ae^2 / r^5
    z_term = 5.0 * x[2] * x[2] / r2
    common = -MU / r3 - j2_term * (1.0 - z_term)
    w2 = OMEGA_E * OMEGA_E
    out[0], out[1], out[2] = x[3], x[4], x[5]
    out[3] = (common + w2) * x[0] + 2.0 * OMEGA_E * x[4] + acc[0]
    out[4] = (common + w2) * x[1] - 2.0 * OMEGA_E * x[3] + acc[1]
    out[5] = (common - 2.0 * j2_term) * x[2] + acc[2]


@numba.njit(cache=True, nogil=True)
def _rk4_step(x, acc, h, k1, k2, k3, k4, w):
    _derivative(x, acc, k1)
    for i in range(6):
        w[i] = x[i] + 0.5 * h * k1[i]
    _derivative(w, acc, k2)
    for i in range(6):
        w[i] = x[i] + 0.5 * h * k2[i]
    _derivative(w, acc, k3)
    for i in range(6):
        w[i] = x[i] + h * k3[i]
    _derivative(w, acc, k4)
    for i in range(6):
        x[i] += h * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0


@numba.njit(cache=True, nogil=True, parallel=True)
def _integrate(params, idx, t, out):
    """out[k] = (x, y, z, vx, vy, vz, clock, drift) of record params[idx[k]] at time t[k]; NaN where idx < 0."""
    for k in numba.prange(idx.shape[0]):  # independent elements: results do not depend on the thread count
        if idx[k] < 0:
            for i in range(8):
                out[k, i] = np.nan
            continue
        p = params[idx[k]]
        x = p[1:7].copy()
        acc = p[7:10]
        k1, k2, k3, k4, w = np.empty(6), np.empty(6), np.empty(6), np.empty(6), np.empty(6)
        left = t[k] - p[TB]
        step = -STEP_S if left < 0.0 else STEP_S
        while abs(left) > 1e-9:
            h = left if abs(left) < STEP_S else step
            _rk4_step(x, acc, h, k1, k2, k3, k4, w)
            left -= h
        for i in range(6):
            out[k, i] = x[i]
        out[k, 6] = -p[TAUN] + p[GAMN] * (t[k] - p[TB])
        out[k, 7] = p[GAMN]


def propagate(params: np.ndarray, idx: np.ndarray, t: np.ndarray, velocity: bool = False):
    """Evaluate GLONASS records ``params[idx]`` at GPS times ``t`` (s since the reference week), both (N,).

    Returns ``pos`` (N, 3) m and ``clk`` (N,) s, and when ``velocity`` also ``vel`` (N, 3) m/s (rotating frame)
    and ``drift`` (N,) s/s; NaN where ``idx < 0``."""
    idx = np.ascontiguousarray(idx, dtype=np.int64)
    out = np.empty((idx.size, 8))
    _integrate(np.ascontiguousarray(params, dtype=float), idx, np.ascontiguousarray(t, dtype=float), out)
    pos, clk = out[:, :3], out[:, 6]
    return (pos, clk, out[:, 3:6], out[:, 7]) if velocity else (pos, clk)


@dataclass
class GlonassRecords:
    """``params`` (R, N_COLS) (tb, position m, velocity m/s, acceleration m/s^2, tau_n s, gamma_n), ``sat`` (R,)
    index into the satellite list, ``healthy`` (R,) bool, ``channel`` (R,) FDMA frequency number k."""

    params: np.ndarray
    sat: np.ndarray
    healthy: np.ndarray
    channel: np.ndarray


class GlonassConstellation(Constellation):
    """GLONASS satellites from broadcast state-vector records (see the module docstring).

    ``channel`` (S,) int: each satellite's FDMA frequency number k from its records (the most frequent value;
    a satellite whose records disagree is an input error raised by the reader)."""

    kind = "broadcast"

    def __init__(self, sat_ids, records: GlonassRecords, source: str, ref_week: int):
        super().__init__(sat_ids, ["MEO"] * len(sat_ids), source, ref_week)
        self.records = records
        tb = records.params[:, TB]
        self.channel = np.zeros(len(sat_ids), dtype=np.int64)  # (S,) FDMA frequency numbers
        self._sel = []
        for s in range(len(sat_ids)):
            mine = records.sat == s
            if mine.any():
                self.channel[s] = np.bincount(records.channel[mine] - min(FREQ_CHANNELS)).argmax() \
                    + min(FREQ_CHANNELS)
            rows = np.flatnonzero(mine & records.healthy)
            self._sel.append(rows[np.argsort(tb[rows], kind="stable")])

    @property
    def channels(self) -> np.ndarray:
        return self.channel

    def select(self, t: np.ndarray) -> np.ndarray:
        """Record index (N, S) for times ``t`` (N, S): the healthy record with the nearest tb (the later on a
        tie) within +-FIT_HALF_S; -1 where none."""
        idx = np.full(t.shape, -1, dtype=np.int64)
        tb = self.records.params[:, TB]
        for s, rows in enumerate(self._sel):
            if rows.size == 0:
                continue
            ts, tbs = t[:, s], tb[rows]
            j = np.searchsorted(tbs, ts, side="right")
            lo, hi = np.clip(j - 1, 0, rows.size - 1), np.clip(j, 0, rows.size - 1)
            pick = np.where(np.abs(tbs[hi] - ts) <= np.abs(ts - tbs[lo]), hi, lo)
            idx[:, s] = np.where(np.abs(ts - tbs[pick]) <= FIT_HALF_S, rows[pick], -1)
        return idx

    def _intervals(self):
        tb = self.records.params[self.records.healthy, TB]
        return tb - FIT_HALF_S, tb + FIT_HALF_S, np.inf

    def _evaluate(self, t, velocity):
        return propagate(self.records.params, self.select(t).ravel(), t.ravel(), velocity)
