"""The constellation object returned by :func:`simkit.constellation.load`.

:class:`Constellation` is the common interface (``sat_ids``, ``system``, ``orbit_type``, ``state``);
:class:`KeplerConstellation` holds Keplerian records (broadcast ephemerides, almanacs, nominal slots) and picks,
for every epoch and satellite, the healthy record with the nearest toe inside that record's validity.
"""
from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from .. import gpstime
from . import kepler
from .errors import ConstellationInputError, NoStateError
from .systems import GEO_MAX_INC_RAD, GEO_MIN_A_M

SECONDS_PER_WEEK = gpstime.SECONDS_PER_WEEK


def _integer_weeks(gps_week) -> np.ndarray:
    """``gps_week`` as int64, or ConstellationInputError when an element is not a whole, finite number."""
    week = np.asarray(gps_week)
    if week.dtype.kind in "iu":
        return week.astype(np.int64)
    if week.dtype.kind != "f":
        raise ConstellationInputError("gps_week", f"found {gps_week!r}; expected an integer GPS week")
    as_float = week.astype(float)
    bad = ~np.isfinite(as_float) | (as_float != np.round(as_float))
    if bad.any():
        raise ConstellationInputError("gps_week", f"found {as_float[bad].ravel()[0]!r}; expected an integer GPS "
                                      "week (fractions of a week go in gps_sow)")
    return as_float.astype(np.int64)


@dataclass
class Klobuchar:
    """Broadcast Klobuchar coefficients: ``alpha`` (s, s/sc, s/sc^2, s/sc^3), ``beta`` (s, s/sc, ...)."""

    alpha: np.ndarray
    beta: np.ndarray


@dataclass(frozen=True)
class TimeOffset:
    """A broadcast system-time offset as the navigation file writes it (RINEX 3 'TIME SYSTEM CORR', RINEX 4
    '> STO'): the difference named by ``kind`` (e.g. "GAGP": Galileo minus GPS time) at GPS time t is
    ``a0 + a1 (t - t_ref)`` s; ``t_ref`` as (GPS week, seconds of week)."""

    kind: str
    a0: float
    a1: float
    t_ref: tuple


@dataclass
class GroupDelays:
    """Broadcast group-delay parameters of one name (e.g. ``"TGD"``), one entry per broadcast record.

    ``sat`` index into the constellation's ``sat_ids``, ``t`` GPS seconds since the reference week, ``value`` s.
    """

    sat: np.ndarray
    t: np.ndarray
    value: np.ndarray


def orbit_types(sqrt_a, inclination) -> np.ndarray:
    """'GEO', 'IGSO' or 'MEO' from the orbit: geosynchronous (a > 40,000 km) with i < 10 deg is GEO."""
    a = np.asarray(sqrt_a, dtype=float) ** 2
    inc = np.abs(np.asarray(inclination, dtype=float))
    geosync = a > GEO_MIN_A_M
    return np.where(geosync & (inc < GEO_MAX_INC_RAD), "GEO", np.where(geosync, "IGSO", "MEO"))


class Constellation:
    """A set of satellites whose states can be evaluated at GPS epochs.

    Attributes: ``sat_ids`` (list of "G01"/"C03"), ``system`` (S,) array of 'G'/'C', ``orbit_type`` (S,)
    array of 'MEO'/'IGSO'/'GEO', ``source`` (text), ``ref_week`` (GPS week that internal seconds count from),
    ``klobuchar`` (dict 'G'/'C' -> :class:`Klobuchar`, only what the source broadcasts).
    """

    kind = "abstract"

    def __init__(self, sat_ids, orbit_type, source: str, ref_week: int, klobuchar=None, group_delays=None):
        self.sat_ids = list(sat_ids)
        self.system = np.array([s[0] for s in self.sat_ids])
        self.orbit_type = np.asarray(orbit_type)
        self.source = source
        self.ref_week = int(ref_week)
        self.klobuchar = dict(klobuchar or {})
        self._delays = dict(group_delays or {})
        self.time_offsets: dict[str, TimeOffset] = {}  # broadcast system-time offsets by kind (read, not applied)

    def __len__(self) -> int:
        return len(self.sat_ids)

    @property
    def channels(self) -> np.ndarray:
        """(S,) int: GLONASS FDMA frequency numbers k (0 for CDMA satellites)."""
        return np.zeros(len(self.sat_ids), dtype=np.int64)

    def __repr__(self) -> str:
        kinds = {s: int(np.sum(self.system == s)) for s in np.unique(self.system)}
        return f"<{type(self).__name__} {self.kind} {kinds} from {self.source}>"

    def _seconds(self, gps_week, gps_sow):
        """Broadcast (week, sow) -> (shape, float seconds since ``ref_week`` flattened)."""
        week, sow = np.broadcast_arrays(_integer_weeks(gps_week), np.asarray(gps_sow, dtype=float))
        t = (week - self.ref_week) * SECONDS_PER_WEEK + sow
        return week.shape, t.ravel()

    def _intervals(self):
        """Where states exist: (lo, hi) arrays of seconds since ``ref_week`` (one interval per record; +-inf when
        always valid) and the period with which they repeat (np.inf: they do not)."""
        raise NotImplementedError

    def covered(self, gps_week, gps_sow) -> np.ndarray:
        """Boolean array (shape of the broadcast times): at least one satellite has a state at that GPS time."""
        shape, t = self._seconds(gps_week, gps_sow)
        lo, hi, period = self._intervals()
        if lo.size == 0:
            return np.zeros(shape, bool)
        if np.isfinite(period):
            t = t - period * np.round((t - 0.5 * (lo.min() + hi.max())) / period)
        order = np.argsort(lo, kind="stable")
        lo, reach = lo[order], np.maximum.accumulate(hi[order])  # reach: furthest end of intervals begun so far
        j = np.searchsorted(lo, t, side="right") - 1
        return ((j >= 0) & (t <= reach[np.maximum(j, 0)])).reshape(shape)

    def validity_span(self, gps_week=None, gps_sow=0.0):
        """First and last GPS epoch with a state, ((week, sow), (week, sow)); None when states exist at every
        epoch (nominal constellations). For repeating almanac records (1024-week copies), the copy nearest to
        (gps_week, gps_sow) (default: the records' own). Gaps inside the span are possible."""
        lo, hi, period = self._intervals()
        if lo.size == 0:
            raise NoStateError(self.source, "no healthy record: no satellite ever has a state")
        first, last = lo.min(), hi.max()
        if not (np.isfinite(first) and np.isfinite(last)):
            return None
        if gps_week is not None and np.isfinite(period):
            t = self._seconds(gps_week, gps_sow)[1][0]
            shift = period * np.round((t - 0.5 * (first + last)) / period)
            first, last = first + shift, last + shift
        return gpstime.normalize(self.ref_week, first), gpstime.normalize(self.ref_week, last)

    def require_states(self, gps_week, gps_sow) -> np.ndarray:
        """:meth:`covered` for the given times, raising :class:`NoStateError` (naming the source, the times and
        the span the source covers) when no satellite has a state at any of them."""
        ok = self.covered(gps_week, gps_sow)
        if ok.any():
            return ok
        shape, t = self._seconds(gps_week, gps_sow)
        asked = [gpstime.normalize(self.ref_week, x) for x in (np.nanmin(t), np.nanmax(t))] if t.size else []
        span = self.validity_span(*asked[0]) if asked else self.validity_span()
        when = f"at {_utc(asked[0])}" if asked and asked[0] == asked[1] else \
            f"from {_utc(asked[0])} to {_utc(asked[1])}" if asked else "at no time given"
        raise NoStateError(self.source, f"no satellite has a state {when}; the source covers "
                           f"{describe_span(span)}", span)

    def state(self, gps_week, gps_sow, velocity: bool = False):
        """Satellite states at GPS times (transmit time), ECEF of that instant.

        ``gps_week`` (int or array) and ``gps_sow`` (s, array) broadcast to a shape T. Returns ``pos`` (T + (S, 3))
        m and ``clock`` (T + (S,)) s = af0 + af1 dt + af2 dt^2 + relativistic term, without group delays; with
        ``velocity=True`` also ``vel`` (T + (S, 3)) m/s (ECEF, rotating frame) and ``drift`` (T + (S,)) s/s.
        NaN where no record is valid at that epoch.
        """
        shape, t = self._seconds(gps_week, gps_sow)
        s = len(self.sat_ids)
        return self._shaped(self._evaluate(np.broadcast_to(t[:, None], (t.size, s)), velocity), shape)

    def state_each(self, gps_week, gps_sow, velocity: bool = False):
        """Like :meth:`state`, but satellite s is evaluated at its own time: ``gps_week``/``gps_sow`` broadcast
        to a shape T + (S,) (e.g. per-satellite transmit times). Same returns as :meth:`state`."""
        shape, t = self._seconds(gps_week, gps_sow)
        s = len(self.sat_ids)
        if not shape or shape[-1] != s:
            raise ConstellationInputError("gps_sow", f"state_each needs times of shape (..., {s}) (one column per "
                                          f"satellite), found {shape}")
        return self._shaped(self._evaluate(t.reshape(-1, s), velocity), shape[:-1])

    def _shaped(self, out, shape):
        s = len(self.sat_ids)
        dims = (shape + (s, 3), shape + (s,), shape + (s, 3), shape + (s,))
        return tuple(a.reshape(d) for a, d in zip(out, dims))  # 2 or 4 arrays

    def _evaluate(self, t, velocity):
        """States at times ``t`` (N, S) (GPS s since ref_week; column s for satellite s) -> flat arrays."""
        raise NotImplementedError

    def group_delay_names(self) -> list[str]:
        """Names of the broadcast group delays this source carries (e.g. TGD, TGD1, TGD2, TGD_B1Cp)."""
        return sorted(self._delays)

    def group_delays(self, gps_week=None, gps_sow=None) -> dict[str, np.ndarray]:
        """Broadcast group delays per satellite: name -> (S,) seconds, NaN where a satellite has none.

        Each value comes from that satellite's broadcast record nearest to (gps_week, gps_sow) (default: the
        middle of the records' span). GPS: ``TGD``; BDS D1/D2: ``TGD1`` (B1I), ``TGD2`` (B2I); BDS CNAV1/2
        (RINEX 4): ``TGD_B1Cp``, ``TGD_B2ap``, ``ISC_B1Cd``, ``ISC_B2ad``.
        """
        out = {}
        for name, d in self._delays.items():
            if gps_week is None:
                t0 = 0.5 * (d.t.min() + d.t.max())
            else:
                t0 = float(self._seconds(gps_week, gps_sow)[1][0])
            vals = np.full(len(self.sat_ids), np.nan)
            order = np.lexsort((np.abs(d.t - t0), d.sat))
            first = np.unique(d.sat[order], return_index=True)[1]
            vals[d.sat[order][first]] = d.value[order][first]
            out[name] = vals
        return out


def _utc(week_sow) -> str:
    return gpstime.gps_to_utc(*week_sow).strftime("%Y-%m-%d %H:%M:%S UTC")


def describe_span(span) -> str:
    """'2026-04-26 22:00:00 UTC to 2026-04-28 01:59:44 UTC' for a :meth:`Constellation.validity_span` result
    (None: 'every epoch')."""
    return "every epoch" if span is None else f"{_utc(span[0])} to {_utc(span[1])}"


@dataclass
class Records:
    """Keplerian records: ``params`` (R, len(kepler.FIELDS)), ``sat`` (R,) index, ``healthy`` (R,) bool,
    ``half_width`` (R,) s validity either side of toe (np.inf: always valid), ``period`` (R,) s or None: a
    record repeats with this period (10-bit almanac weeks: 1024 weeks) and each query uses its nearest copy.
    ``after_toe`` (R,) bool or None: the record is valid only after its toe, for ``half_width`` s, and the latest
    such record is used instead of the nearest (Galileo: a navigation batch is broadcast after its toe and holds
    for 4 h; RTKLIB's ``seleph`` takes the latest I/NAV record with toe before t the same way)."""

    params: np.ndarray
    sat: np.ndarray
    healthy: np.ndarray
    half_width: np.ndarray
    period: np.ndarray | None = None
    after_toe: np.ndarray | None = None


class KeplerConstellation(Constellation):
    """Constellation of Keplerian records (broadcast ephemeris, almanac or nominal slots)."""

    def __init__(self, sat_ids, records: Records, source: str, ref_week: int, kind: str,
                 klobuchar=None, group_delays=None):
        p = records.params
        # orbit type from each satellite's first healthy record (or any record)
        otype = []
        for s in range(len(sat_ids)):
            rows = np.flatnonzero((records.sat == s) & records.healthy)
            rows = rows if rows.size else np.flatnonzero(records.sat == s)
            r = rows[0]
            otype.append(orbit_types(p[r, kepler.COL["sqrt_a"]], p[r, kepler.COL["i0"]]).item())
        super().__init__(sat_ids, otype, source, ref_week, klobuchar, group_delays)
        self.kind = kind
        self.records = records
        self.channel = np.zeros(len(sat_ids), dtype=np.int64)  # FDMA channels (nominal GLONASS sets them)
        toe = p[:, kepler.COL["toe"]]
        period = records.period if records.period is not None else np.full(len(toe), np.inf)
        after = records.after_toe if records.after_toe is not None else np.zeros(len(toe), bool)
        self._sel = []
        for s in range(len(sat_ids)):
            rows = np.flatnonzero((records.sat == s) & records.healthy)
            rows = rows[np.argsort(toe[rows], kind="stable")]
            per = np.unique(period[rows])
            if per.size > 1:
                raise ValueError(f"{sat_ids[s]}: records with different repeat periods")
            self._sel.append((rows, toe[rows], records.half_width[rows], per[0] if per.size else np.inf,
                              bool(after[rows].all()) if rows.size else False))
        # the same tables flattened for the selection kernel: satellite s owns entries bounds[s]:bounds[s + 1]
        self._flat = (np.concatenate([x[0] for x in self._sel]).astype(np.int64) if self._sel else
                      np.zeros(0, np.int64),
                      np.concatenate([x[1] for x in self._sel]).astype(float) if self._sel else np.zeros(0),
                      np.concatenate([x[2] for x in self._sel]).astype(float) if self._sel else np.zeros(0),
                      np.cumsum([0] + [x[0].size for x in self._sel]).astype(np.int64),
                      np.array([x[3] for x in self._sel], dtype=float),
                      np.array([x[4] for x in self._sel], dtype=bool),
                      np.array([x[1][0] if x[0].size else 0.0 for x in self._sel]))

    @property
    def channels(self) -> np.ndarray:
        return self.channel

    def select(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Record index (N, S) for times ``t`` (N, S) (GPS s since ``ref_week``, column s for satellite s): the
        healthy record with the nearest toe (the later one on a tie) whose validity covers t; -1 where none.
        Also returns the times to evaluate at (``t`` moved by whole periods for repeating almanac records)."""
        rows, toe, half, bounds, period, after, first = self._flat
        t_eval = np.array(t, dtype=float)
        rep = np.isfinite(period)
        if rep.any():  # repeating records: the copy nearest to each time
            t_eval[:, rep] -= period[rep] * np.round((t_eval[:, rep] - first[rep]) / period[rep])
        idx = np.empty(t_eval.shape, dtype=np.int64)
        _select(rows, toe, half, bounds, after, np.ascontiguousarray(t_eval), idx)
        return idx, t_eval

    def _intervals(self):
        r = self.records
        toe = r.params[r.healthy, kepler.COL["toe"]]
        half = r.half_width[r.healthy]
        after = r.after_toe[r.healthy] if r.after_toe is not None else np.zeros(toe.size, bool)
        period = np.unique(r.period[r.healthy]) if r.period is not None else np.array([np.inf])
        return np.where(after, toe, toe - half), toe + half, float(period.min()) if period.size else np.inf

    def _evaluate(self, t, velocity):
        idx, t_eval = self.select(t)
        return kepler.propagate(self.records.params, idx.ravel(), t_eval.ravel(), velocity)


@numba.njit(cache=True, nogil=True)
def _select(rows, toe, half, bounds, after, t, idx):
    """Record index per (time, satellite) (see :meth:`KeplerConstellation.select`): satellite s's healthy records
    are ``rows[bounds[s]:bounds[s + 1]]`` sorted by ``toe``, valid ``half`` s either side (``after[s]``: only after,
    the latest toe strictly before t)."""
    for s in range(t.shape[1]):
        lo_s, hi_s = bounds[s], bounds[s + 1]
        for n in range(t.shape[0]):
            idx[n, s] = -1
            if hi_s == lo_s:
                continue
            ts = t[n, s]
            if after[s]:  # np.searchsorted(toe, ts, side="left") - 1
                j = lo_s + np.searchsorted(toe[lo_s:hi_s], ts) - 1
                if j >= lo_s and ts - toe[j] <= half[j]:
                    idx[n, s] = rows[j]
                continue
            j = lo_s + np.searchsorted(toe[lo_s:hi_s], ts, side="right")  # toe[j-1] <= t < toe[j]
            lo, hi = max(j - 1, lo_s), min(j, hi_s - 1)
            pick = hi if abs(toe[hi] - ts) <= abs(ts - toe[lo]) else lo
            if abs(ts - toe[pick]) <= half[pick]:
                idx[n, s] = rows[pick]


class CombinedConstellation(Constellation):
    """Several constellations read from one source (a mixed navigation file: Keplerian systems and GLONASS),
    seen as one: ``sat_ids`` are the parts' in order, and all parts count seconds from the same ``ref_week``.
    ``records`` is the first (Keplerian) part's record table, whose satellite indices are valid in ``sat_ids``
    because that part comes first."""

    def __init__(self, parts: list[Constellation], source: str):
        if len({p.ref_week for p in parts}) != 1:
            raise ValueError("combined constellations must share their reference week")
        klob = {k: v for p in reversed(parts) for k, v in p.klobuchar.items()}
        super().__init__([s for p in parts for s in p.sat_ids], np.concatenate([p.orbit_type for p in parts]),
                         source, parts[0].ref_week, klob)
        self.parts = list(parts)
        self.kind = parts[0].kind
        self.time_offsets = {k: v for p in reversed(parts) for k, v in p.time_offsets.items()}
        self._bounds = np.cumsum([0] + [len(p.sat_ids) for p in parts])

    @property
    def channels(self) -> np.ndarray:
        return np.concatenate([p.channels for p in self.parts])

    def part(self, system: str):
        """The part holding satellites of ``system`` ('R' -> the GLONASS part), or None."""
        return next((p for p in self.parts if system in set(p.system)), None)

    @property
    def records(self):
        return self.parts[0].records

    def _intervals(self):
        spans = [p._intervals() for p in self.parts]
        return (np.concatenate([s[0] for s in spans]), np.concatenate([s[1] for s in spans]),
                min(s[2] for s in spans))

    def _evaluate(self, t, velocity):
        n = t.shape[0]
        outs = []
        for p, a, b in zip(self.parts, self._bounds[:-1], self._bounds[1:]):
            res = p._evaluate(np.ascontiguousarray(t[:, a:b]), velocity)
            outs.append([r.reshape((n, b - a) + r.shape[1:]) for r in res])
        return tuple(np.concatenate(cols, axis=1).reshape((-1,) + cols[0].shape[2:]) for cols in zip(*outs))

    def group_delay_names(self) -> list[str]:
        return sorted({n for p in self.parts for n in p.group_delay_names()})

    def group_delays(self, gps_week=None, gps_sow=None) -> dict[str, np.ndarray]:
        out: dict[str, np.ndarray] = {}
        for p, a, b in zip(self.parts, self._bounds[:-1], self._bounds[1:]):
            for name, vals in p.group_delays(gps_week, gps_sow).items():
                out.setdefault(name, np.full(len(self.sat_ids), np.nan))[a:b] = vals
        return out
