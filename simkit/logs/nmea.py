"""NMEA 0183 logs: GGA (position, time of day), RMC (date, horizontal velocity), VTG (horizontal velocity),
GST (position standard deviations); any talker (GP, GN, GL, GA, BD, GB). Other sentences are skipped.

A small parser of our own rather than ``pynmea2``: the four sentences are a few fields each, and reading them
here gives one error naming the line for a bad checksum or field, which is what a log replay needs.

Each GGA with a fix is one sample; an RMC or GST joins the GGA of the same UTC time of day (before or after it),
a VTG the epoch of the time-bearing sentence before it. The date is
RMC's; a log without RMC takes the date of ``scenario.start`` and rolls over at midnight. GGA quality 0 (no fix)
is skipped. Height = antenna altitude above the geoid + geoid separation (both in GGA): ellipsoidal.
"""
from __future__ import annotations

from datetime import date, datetime, timezone

import numpy as np

from .. import frames
from ..errors import DataFileError
from .record import Record, utc_to_gps_arrays

KNOT = 1852.0 / 3600.0


def _checksum(body: str) -> int:
    c = 0
    for ch in body.encode("ascii", "replace"):
        c ^= ch
    return c


def _angle(value: str, hemi: str, width: int) -> float:
    deg = float(value[:width]) + float(value[width:]) / 60.0
    return -deg if hemi in ("S", "W") else deg


def _tod(value: str) -> float:
    return int(value[0:2]) * 3600.0 + int(value[2:4]) * 60.0 + float(value[4:])


def read(path, date_hint: date | None = None) -> Record:
    """The GGA fixes of an NMEA file, with RMC/VTG velocity and GST sigmas where present."""
    src = str(path)
    try:
        text = open(path, encoding="ascii", errors="replace").read()
    except OSError as exc:
        raise DataFileError(src, f"cannot read: {exc}") from None
    fixes = _parse(src, text)
    if not fixes:
        raise DataFileError(src, "no GGA fix (quality > 0) found: NMEA logs need GGA for positions and heights")
    week, sow = utc_to_gps_arrays(_utc_ns(src, fixes, date_hint))
    lat, lon, h = (np.radians([e["lat"] for e in fixes]), np.radians([e["lon"] for e in fixes]),
                   np.array([e["h"] for e in fixes]))
    vel = np.array([e.get("vel", (np.nan, np.nan, np.nan)) for e in fixes])
    sig = np.array([e.get("sigma", (np.nan, np.nan, np.nan)) for e in fixes])
    return Record(week, sow, frames.lla_to_ecef(lat, lon, h), np.array([e["line"] for e in fixes]), src,
                  sigma_enu=sig if np.isfinite(sig).all() else None,
                  vel_enu=vel if np.isfinite(vel).any() else None)


def _fields(src, n, line):
    """The comma-separated fields of a sentence after its checksum is verified."""
    if not line.startswith("$"):
        raise DataFileError(src, f"expected an NMEA sentence starting with '$', got {line[:20]!r}", n)
    body, star, check = line[1:].partition("*")
    if star:
        try:
            ok = int(check[:2], 16) == _checksum(body)
        except ValueError:
            ok = False
        if not ok:
            raise DataFileError(src, f"bad checksum *{check} (computed *{_checksum(body):02X})", n)
    return body.split(",")


class _Epochs:
    """One sample per GGA with a fix, in file order; RMC / GST / VTG data join the GGA of their time of day."""

    def __init__(self):
        self.fixes: list[dict] = []
        self.pending: dict[float, dict] = {}   # data that came before the GGA of their epoch
        self.current = None                    # time of day of the last time-bearing sentence (VTG has none)

    def of(self, tod):
        if self.fixes and self.fixes[-1]["tod"] == tod:
            return self.fixes[-1]
        return self.pending.setdefault(tod, {})

    def gga(self, f, n):
        if len(f) < 12:
            raise ValueError("GGA needs 14 fields")
        if not f[1]:
            return
        self.current = tod = _tod(f[1])
        if not f[6] or int(f[6]) == 0 or not f[2]:
            return
        if not f[9] or not f[11]:
            raise ValueError("altitude or geoid separation empty: the ellipsoidal height is unknown")
        self.fixes.append(dict(self.pending.pop(tod, {}), tod=tod, lat=_angle(f[2], f[3], 2),
                               lon=_angle(f[4], f[5], 3), h=float(f[9]) + float(f[11]), line=n))

    def rmc(self, f, n):
        if len(f) < 10:
            raise ValueError("RMC needs at least 10 fields")
        if not f[1]:
            return
        self.current = tod = _tod(f[1])
        e = self.of(tod)
        if f[9]:
            yy = int(f[9][4:6])      # two digits: 80-99 are 1980-1999 (GPS began in 1980)
            e["day"] = date((1900 if yy >= 80 else 2000) + yy, int(f[9][2:4]), int(f[9][0:2]))
        if f[2] == "A" and f[7] and f[8]:
            _velocity(e, float(f[7]) * KNOT, float(f[8]))

    def vtg(self, f, n):
        if self.current is not None and len(f) > 7 and f[1] and f[7]:
            _velocity(self.of(self.current), float(f[7]) / 3.6, float(f[1]))

    def gst(self, f, n):
        if len(f) < 9:
            raise ValueError("GST needs 9 fields")
        if f[1] and f[6] and f[7] and f[8]:
            self.current = tod = _tod(f[1])
            self.of(tod)["sigma"] = (float(f[7]), float(f[6]), float(f[8]))


def _parse(src, text) -> list[dict]:
    epochs = _Epochs()
    handlers = {"GGA": epochs.gga, "RMC": epochs.rmc, "VTG": epochs.vtg, "GST": epochs.gst}
    for n, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line:
            continue
        f = _fields(src, n, line)
        handler = handlers.get(f[0][-3:])
        if handler is None:
            continue
        try:
            handler(f, n)
        except (ValueError, IndexError) as exc:
            raise DataFileError(src, f"malformed {f[0][-3:]} sentence: {exc}", n) from None
    return epochs.fixes


def _utc_ns(src, fixes, date_hint) -> np.ndarray:
    """UTC nanoseconds since 1970 of the fixes: RMC dates where given, else ``date_hint`` rolled at midnight."""
    dated = [e["day"] for e in fixes if "day" in e]
    if not dated and date_hint is None:
        raise DataFileError(src, "no RMC date and no date given: set scenario.start")
    day, last, ns = (dated[0] if dated else date_hint), None, []
    for e in fixes:
        if "day" in e:
            day = e["day"]
        elif last is not None and e["tod"] < last - 43200.0:     # midnight without an RMC date
            day = date.fromordinal(day.toordinal() + 1)
        last = e["tod"]
        ns.append(int(datetime(day.year, day.month, day.day, tzinfo=timezone.utc).timestamp()) * 10**9
                  + int(round(e["tod"] * 1e9)))
    return np.array(ns, dtype=np.int64)


def _velocity(epoch: dict, speed: float, course_deg: float) -> None:
    c = np.radians(course_deg)
    epoch["vel"] = (speed * np.sin(c), speed * np.cos(c), np.nan)
