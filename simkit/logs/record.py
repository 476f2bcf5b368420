"""What every log reader returns: timestamped samples in GPS time, and their conversion to a :class:`Track`."""
from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime, timezone

import numpy as np

from .. import gpstime
from ..trajectory.logged import Track


@dataclass(frozen=True)
class Record:
    """K samples of a log: GPS time as ``week`` (K,) int and ``sow`` (K,) s; ``pos_ecef`` (K, 3) m; optional
    ``sigma_enu`` (K, 3) m, ``vel_enu`` (K, 3) m/s (NaN for a component not logged), ``sigma_vel`` (K, 3) m/s,
    ``euler`` (K, 3) rad [pitch, roll, heading]; ``line`` (K,) the line (or record) of each sample in ``source``."""

    week: np.ndarray
    sow: np.ndarray
    pos_ecef: np.ndarray
    line: np.ndarray
    source: str
    sigma_enu: np.ndarray | None = None
    vel_enu: np.ndarray | None = None
    sigma_vel: np.ndarray | None = None
    euler: np.ndarray | None = None

    def track(self, week0: int, sow0: float, t_min: float, t_max: float) -> Track:
        """The samples within [t_min, t_max] s of the GPS epoch (week0, sow0), times relative to it."""
        t = gpstime.diff_seconds(self.week, self.sow, week0, sow0)
        f = lambda a: None if a is None else np.asarray(a, float)
        full = Track(t, f(self.pos_ecef), np.asarray(self.line), self.source, f(self.sigma_enu), f(self.vel_enu),
                     f(self.sigma_vel), f(self.euler))
        return full.take(np.nonzero((t >= t_min) & (t <= t_max))[0])

    def span_text(self) -> str:
        """The log's first and last epoch in UTC (for messages)."""
        first = gpstime.gps_to_utc(int(self.week[0]), float(self.sow[0]))
        last = gpstime.gps_to_utc(int(self.week[-1]), float(self.sow[-1]))
        return f"{first:%Y-%m-%dT%H:%M:%S}Z to {last:%Y-%m-%dT%H:%M:%S}Z"


def utc_to_gps_arrays(utc_ns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """UTC instants as int64 nanoseconds since 1970 (K,) -> GPS (week (K,), sow (K,)), with the leap seconds of
    the first instant (a log across a leap second is off by 1 s after it)."""
    utc_ns = np.asarray(utc_ns, dtype=np.int64)
    first = datetime.fromtimestamp(int(utc_ns[0] // 10**9), tz=timezone.utc)
    week0, sow0 = gpstime.utc_to_gps(first)
    offset = (utc_ns - (utc_ns[0] // 10**9) * 10**9) * 1e-9
    return gpstime.add_seconds(np.full(len(utc_ns), week0), sow0, offset)


def iso_ns(text: str) -> int:
    """ISO 8601 UTC text (``2026-04-27T08:00:00.25Z``) -> int64 ns since 1970; ValueError if malformed."""
    t = gpstime.parse_utc(text.strip())
    whole = int(t.replace(microsecond=0).timestamp())
    return whole * 10**9 + t.microsecond * 1000
