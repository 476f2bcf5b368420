"""GPS time, BeiDou time and UTC.

Absolute epochs travel as ``(week, sow)`` pairs (GPS week, seconds of week); relative times as float64 seconds
since the scenario start. BDT = GPST - 14 s and BDS week = GPS week - 1356 (BDT started 2006-01-01 00:00 UTC,
GPS week 1356, sow 14). Leap seconds come from skyfield's built-in table (no network).
"""
from __future__ import annotations

from datetime import datetime, timedelta, timezone
from functools import lru_cache

import numpy as np

SECONDS_PER_WEEK = 604800.0
GPS_EPOCH = datetime(1980, 1, 6, tzinfo=timezone.utc)
GPS_MINUS_TAI = -19.0
BDT_MINUS_GPST = -14.0
BDS_WEEK_OFFSET = 1356
SECONDS_PER_DAY = 86400.0
UNIX_EPOCH_JD = 2440587.5                                                     # 1970-01-01 00:00 as a Julian date
GPS_EPOCH_JD = UNIX_EPOCH_JD + GPS_EPOCH.timestamp() / SECONDS_PER_DAY        # 2444244.5: 1980-01-06 00:00
GPS_EPOCH_ORDINAL = GPS_EPOCH.date().toordinal()                              # proleptic Gregorian day number
ALMANAC_ROLLOVER_WEEKS = 1024                                                 # 10-bit broadcast week numbers


@lru_cache(maxsize=1)
def timescale():
    """skyfield's timescale built from its bundled leap-second and Delta-T tables (never downloads)."""
    from skyfield.api import load

    return load.timescale(builtin=True)


@lru_cache(maxsize=1)
def leap_table() -> tuple[np.ndarray, np.ndarray]:
    """skyfield's built-in leap-second table: the UTC Julian dates of the steps and TAI - UTC (s) from each on.

    Read from skyfield's bundled data file (the arrays ``timescale(builtin=True)`` is built from) without importing
    skyfield, whose import costs a truth + IMU run 0.05 s; through skyfield's timescale when the file is not where
    this skyfield version keeps it."""
    import importlib.util
    from pathlib import Path

    try:
        spec = importlib.util.find_spec("skyfield")
        with np.load(Path(spec.submodule_search_locations[0]) / "data" / "iers.npz") as arrays:
            return arrays["leap_dates"], arrays["leap_offsets"]
    except (AttributeError, TypeError, IndexError, OSError, KeyError, ValueError):
        ts = timescale()
        return ts.leap_dates, ts.leap_offsets


def leap_seconds(utc: datetime) -> float:
    """TAI - UTC in seconds at a UTC instant (from skyfield's built-in table)."""
    dates, offsets = leap_table()
    utc = _aware(utc)
    jd = 2440587.5 + utc.timestamp() / 86400.0
    i = np.searchsorted(dates, jd, side="right") - 1
    return float(offsets[i]) if i >= 0 else 10.0


def _aware(t: datetime) -> datetime:
    return t if t.tzinfo else t.replace(tzinfo=timezone.utc)


def utc_to_gps(utc: datetime) -> tuple[int, float]:
    """UTC datetime -> (GPS week, seconds of week)."""
    utc = _aware(utc)
    elapsed = (utc - GPS_EPOCH) / timedelta(microseconds=1) / 1e6  # exact to the microsecond
    total = elapsed + leap_seconds(utc) + GPS_MINUS_TAI
    week = int(total // SECONDS_PER_WEEK)
    return week, total - week * SECONDS_PER_WEEK


def gps_to_utc(week: int, sow: float) -> datetime:
    """(GPS week, seconds of week) -> UTC datetime (microsecond resolution)."""
    guess = GPS_EPOCH + timedelta(weeks=int(week), seconds=float(sow))
    leap = leap_seconds(guess - timedelta(seconds=20))
    utc = guess - timedelta(seconds=leap + GPS_MINUS_TAI)
    # near a leap second the table lookup must use the result, not the guess
    leap2 = leap_seconds(utc)
    if leap2 != leap:
        utc = guess - timedelta(seconds=leap2 + GPS_MINUS_TAI)
    return utc


def parse_utc(text: str) -> datetime:
    """ISO 8601 text -> aware UTC datetime; a naive time is taken as UTC. Raises ValueError."""
    t = datetime.fromisoformat(text.replace("Z", "+00:00"))
    return _aware(t).astimezone(timezone.utc)


def normalize(week, sow):
    """Carry whole weeks out of ``sow`` so that 0 <= sow < 604800. Works on scalars and arrays."""
    week = np.asarray(week)
    sow = np.asarray(sow, dtype=float)
    carry = np.floor(sow / SECONDS_PER_WEEK)
    carry = np.where(np.isfinite(carry), carry, 0.0)  # a NaN time stays NaN in sow, its week unchanged
    week = week + carry.astype(np.int64)
    sow = sow - carry * SECONDS_PER_WEEK
    if week.ndim == 0:
        return int(week), float(sow)
    return week, sow


def add_seconds(week, sow, seconds):
    """(week, sow) + seconds -> normalised (week, sow); vectorised over ``seconds``."""
    return normalize(week, np.asarray(sow, dtype=float) + np.asarray(seconds, dtype=float))


def diff_seconds(week_a, sow_a, week_b, sow_b):
    """(week_a, sow_a) - (week_b, sow_b) in seconds, computed without forming large float totals."""
    return (np.asarray(week_a) - np.asarray(week_b)) * SECONDS_PER_WEEK + (
        np.asarray(sow_a, dtype=float) - np.asarray(sow_b, dtype=float)
    )


def gps_to_bdt(week, sow):
    """GPS (week, sow) -> BDS (week, sow of BDT)."""
    w, s = add_seconds(week, sow, BDT_MINUS_GPST)
    return w - BDS_WEEK_OFFSET, s


def bdt_to_gps(bds_week, bds_sow):
    """BDS (week, sow of BDT) -> GPS (week, sow)."""
    return add_seconds(np.asarray(bds_week) + BDS_WEEK_OFFSET, bds_sow, -BDT_MINUS_GPST)
