"""Two-line element sets propagated with skyfield's EarthSatellite (SGP4), converted TEME -> ITRS by skyfield.

Satellites are identified from the name line: '(PRN 13)' -> G13 (GPS sets), '(C19)' -> C19 (BeiDou sets),
'GSAT0101 (GALILEO-PFM)' or '(PRN E11)' -> E11 (Galileo sets, see :mod:`.galileo_satellites`); objects
without such an id in their name are skipped. TLEs carry no clock: the clock and drift are zero.
States are returned within ``validity_days`` (default 7) of each TLE's epoch, NaN outside.
"""
from __future__ import annotations

import re

import numpy as np

from .. import gpstime
from ..errors import DataFileError
from . import galileo_satellites
from .model import Constellation, orbit_types

DEFAULT_VALIDITY_DAYS = 7.0
DAY = gpstime.SECONDS_PER_DAY
WEEK = gpstime.SECONDS_PER_WEEK
# GPS time = TAI - 19 s: a GPS-time Julian date is the TAI Julian date minus 19 s; both count from GPS_EPOCH_JD
TAI_MINUS_GPS = -gpstime.GPS_MINUS_TAI
_PRN = re.compile(r"\(PRN\s*(\d+)\)")
_BDS = re.compile(r"\(C\s*(\d+)\)")


def is_tle(lines) -> bool:
    body = [ln for ln in lines if ln.strip()]
    return any(ln.startswith("1 ") and len(ln) >= 69 for ln in body[:3]) and \
        any(ln.startswith("2 ") and len(ln) >= 69 for ln in body[:4])


def _checksum_ok(line: str) -> bool:
    total = sum(int(ch) if ch.isdigit() else (1 if ch == "-" else 0) for ch in line[:68])
    return line[68].isdigit() and total % 10 == int(line[68])


def _sat_id(name: str):
    m = _PRN.search(name)
    if m and ("GPS" in name.upper() or "NAVSTAR" in name.upper()):
        return f"G{int(m.group(1)):02d}"
    m = _BDS.search(name)
    if m and "BEIDOU" in name.upper():
        return f"C{int(m.group(1)):02d}"
    return galileo_satellites.sat_id(name)


class TleConstellation(Constellation):
    """Satellites from TLEs; states by SGP4 (skyfield), ITRS (= ECEF, no polar motion), zero clocks."""

    kind = "tle"

    def __init__(self, sats, source, validity_days):
        from skyfield.api import EarthSatellite

        ts = gpstime.timescale()
        self._sats = [EarthSatellite(l1, l2, name, ts) for _, name, l1, l2, _ in sats]
        epoch_tai = np.array([s.epoch.tai for s in self._sats])
        ref_week = int(np.floor((epoch_tai.min() - gpstime.GPS_EPOCH_JD) * DAY / WEEK))
        self._epoch = ((epoch_tai - gpstime.GPS_EPOCH_JD) * DAY - TAI_MINUS_GPS) - ref_week * WEEK
        self._half = validity_days * DAY
        sqrt_a = [(398600.4418 / (s.model.no_kozai / 60.0) ** 2) ** (1 / 6) * 1e3 ** 0.5 for s in self._sats]
        otype = orbit_types(np.array(sqrt_a), np.array([s.model.inclo for s in self._sats]))
        super().__init__([s[0] for s in sats], otype, source, ref_week)

    def _intervals(self):
        return self._epoch - self._half, self._epoch + self._half, np.inf

    def _evaluate(self, t, velocity):
        from skyfield.framelib import itrs

        ts = gpstime.timescale()
        n, s = t.shape
        pos = np.full((n, s, 3), np.nan)
        vel = np.full((n, s, 3), np.nan)
        for k, sat in enumerate(self._sats):
            ok = np.abs(t[:, k] - self._epoch[k]) <= self._half
            if not ok.any():
                continue
            tt = t[ok, k]
            days = np.floor(tt / DAY)
            whole = gpstime.GPS_EPOCH_JD + self.ref_week * (WEEK / DAY) + days
            frac = (tt - days * DAY + TAI_MINUS_GPS) / DAY
            r, v = sat.at(ts.tai_jd(whole, frac)).frame_xyz_and_velocity(itrs)
            pos[ok, k] = r.m.T
            vel[ok, k] = v.m_per_s.T
        clk = np.where(np.isnan(pos[..., 0]), np.nan, 0.0)
        out = (pos.reshape(-1, 3), clk.ravel())
        return out + (vel.reshape(-1, 3), clk.ravel()) if velocity else out


def read(path, lines, validity_days: float = DEFAULT_VALIDITY_DAYS) -> TleConstellation:
    """Parse a 3-line (name + 2 lines) TLE set; only satellites with a GPS, BDS or Galileo id in their name are
    kept."""
    body = [(i, ln.rstrip()) for i, ln in enumerate(lines, 1) if ln.strip()]
    sats, k = [], 0
    while k < len(body):
        i, line = body[k]
        if line.startswith("1 ") and len(line) >= 69:
            name, l1n = "", i
        else:
            name, k = line.strip(), k + 1
            if k >= len(body):
                raise DataFileError(path, f"TLE for {name!r} is truncated: expected line 1", i)
        l1n, l1 = body[k]
        if k + 1 >= len(body):
            raise DataFileError(path, "TLE is truncated: expected line 2", l1n)
        l2n, l2 = body[k + 1]
        for ln_no, ln, tag in ((l1n, l1, "1"), (l2n, l2, "2")):
            if not (ln.startswith(tag + " ") and len(ln) >= 69):
                raise DataFileError(path, f"expected TLE line {tag} (69 columns starting with '{tag} ')", ln_no)
            if not _checksum_ok(ln):
                raise DataFileError(path, f"TLE line {tag} checksum mismatch", ln_no)
        sid = _sat_id(name)
        if sid is not None:
            sats.append((sid, name, l1, l2, float(l1[18:32])))
        k += 2
    if not sats:
        raise DataFileError(path, "no GPS, BDS or Galileo satellite with an id in its name "
                            "('(PRN nn)', '(Cnn)', 'GSATnnnn' or '(PRN Enn)')")
    best = {}
    for sat in sats:  # the newest TLE per PRN
        if sat[0] not in best or _epoch_key(sat[4]) > _epoch_key(best[sat[0]][4]):
            best[sat[0]] = sat
    return TleConstellation([best[k] for k in sorted(best)], str(path), validity_days)


def _epoch_key(yyddd: float) -> float:
    yy = int(yyddd // 1000)
    return (2000 + yy if yy < 57 else 1900 + yy) * 1000 + yyddd % 1000
