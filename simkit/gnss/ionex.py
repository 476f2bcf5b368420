"""IONEX 1.0 global ionosphere maps: parser and vertical-TEC interpolation.

Format (Schaer, Gurtner, Feltens 1998, "IONEX: The IONosphere Map EXchange Format Version 1"): 60 columns of data
and a label in columns 61-80 on every header line; two-dimensional TEC maps (``MAP DIMENSION`` 2, one shell height)
given row by row per latitude (``LAT/LON1/LON2/DLON/H``, then the longitudes in 16I5 lines), in units of
10^EXPONENT TECU, 9999 where no value is available. Epochs are UT; they are turned into GPS time with the leap
seconds of the first map. RMS and height maps are skipped.

Interpolation is the format description's recommended scheme (its eq. 3, as RTKLIB's ``iontec``): linear in time
between the consecutive maps i, i+1, each read at the longitude rotated with the Sun, lon + (t - T_i) 360 deg/day,
and bilinear in latitude and longitude inside a map. A point outside the grid's latitudes or next to a missing value
is NaN.
"""
from __future__ import annotations

import gzip
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from .. import gpstime
from ..errors import DataFileError

TECU = 1e16                 # electrons per m^2
IONO_CONSTANT = 40.3        # m^3/s^2: first-order group delay = 40.3 TEC / f^2
_MISSING = 9999
_MAP_LABELS = ("LAT/LON1/LON2/DLON/H", "END OF TEC MAP", "START OF TEC MAP", "EPOCH OF CURRENT MAP", "END OF FILE",
               "START OF RMS MAP")


@dataclass(frozen=True)
class IonexMaps:
    """TEC maps of one IONEX file: map epochs ``t_s`` (T,) s after the first map, whose GPS time is
    (``first_week``, ``first_sow``); grid ``lat_deg`` (L,) ascending and ``lon_deg`` (K,) ascending; ``tec_tecu``
    (T, L, K) with NaN where missing; shell height and base radius in m; the mapping function named in the file."""

    path: str
    first_week: int
    first_sow: float
    t_s: np.ndarray
    lat_deg: np.ndarray
    lon_deg: np.ndarray
    tec_tecu: np.ndarray
    height_m: float
    base_radius_m: float
    mapping_function: str

    def vtec(self, week, sow, lat_rad, lon_rad) -> np.ndarray:
        """Vertical TEC (TECU) at GPS times (``week``, ``sow``) and geodetic ``lat_rad``/``lon_rad`` (broadcast
        together); NaN outside the maps' times or latitudes."""
        dt = np.asarray(gpstime.diff_seconds(week, sow, self.first_week, self.first_sow), dtype=float)
        lat = np.degrees(np.asarray(lat_rad, dtype=float))
        lon = np.degrees(np.asarray(lon_rad, dtype=float))
        dt, lat, lon = np.broadcast_arrays(dt, lat, lon)
        i = np.clip(np.searchsorted(self.t_s, dt, side="right") - 1, 0, max(self.t_s.size - 2, 0))
        j = np.clip(np.searchsorted(self.lat_deg, lat, side="right") - 1, 0, self.lat_deg.size - 2)
        wy = (lat - self.lat_deg[j]) / (self.lat_deg[j + 1] - self.lat_deg[j])
        eps = 1e-9
        inside = (lat >= self.lat_deg[0] - eps) & (lat <= self.lat_deg[-1] + eps)

        def grid(ti):
            lon_i = lon + (dt - self.t_s[ti]) * (360.0 / 86400.0)     # the map rotated with the Sun
            if self.lon_deg[-1] - self.lon_deg[0] >= 360.0 - 1e-9:
                lon_i = self.lon_deg[0] + np.mod(lon_i - self.lon_deg[0], 360.0)
            k = np.clip(np.searchsorted(self.lon_deg, lon_i, side="right") - 1, 0, self.lon_deg.size - 2)
            wx = (lon_i - self.lon_deg[k]) / (self.lon_deg[k + 1] - self.lon_deg[k])
            g = self.tec_tecu
            value = ((1 - wy) * (1 - wx) * g[ti, j, k] + (1 - wy) * wx * g[ti, j, k + 1]
                     + wy * (1 - wx) * g[ti, j + 1, k] + wy * wx * g[ti, j + 1, k + 1])
            ok = (lon_i >= self.lon_deg[0] - eps) & (lon_i <= self.lon_deg[-1] + eps)
            return np.where(ok, value, np.nan)

        if self.t_s.size == 1:
            out = grid(np.zeros_like(i))
            inside &= np.abs(dt) < 1e-6
        else:
            wt = (dt - self.t_s[i]) / (self.t_s[i + 1] - self.t_s[i])
            out = (1 - wt) * grid(i) + wt * grid(i + 1)
            inside &= (dt >= self.t_s[0]) & (dt <= self.t_s[-1])
        return np.where(inside, out, np.nan)

    def covers(self, week, sow) -> bool:
        """Whether every GPS time (``week``, ``sow``) lies within the maps' epochs."""
        dt = np.asarray(gpstime.diff_seconds(week, sow, self.first_week, self.first_sow), dtype=float)
        return bool(np.all((dt >= self.t_s[0] - 1e-6) & (dt <= self.t_s[-1] + 1e-6)))


def slant_factor(el, base_radius_m: float, height_m: float):
    """Single-layer mapping 1/cos(z') with sin(z') = R/(R + H) cos(el): slant TEC over vertical TEC."""
    s = base_radius_m / (base_radius_m + height_m) * np.cos(el)
    return 1.0 / np.sqrt(1.0 - s * s)


def read_ionex(path) -> IonexMaps:
    """Parse the IONEX file ``path`` (plain or .gz). Raises DataFileError naming the file, the line and what was
    expected."""
    path = Path(path)
    try:
        raw = gzip.open(path, "rt", encoding="ascii", errors="replace") if path.suffix == ".gz" else \
            open(path, "rt", encoding="ascii", errors="replace")
        with raw:
            lines = raw.read().splitlines()
    except OSError as exc:
        raise DataFileError(path, f"cannot read IONEX file: {exc.strerror or exc}") from None
    return _IonexReader(path, lines).parse()


class _IonexReader:
    def __init__(self, path: Path, lines: list[str]):
        self.path, self.lines, self.n = path, lines, 0

    def error(self, message: str, line: int | None = None) -> DataFileError:
        return DataFileError(self.path, message, line if line is not None else self.n)

    def next(self, what: str) -> tuple[str, str]:
        if self.n >= len(self.lines):
            raise self.error(f"file ends early: expected {what}", len(self.lines))
        text = self.lines[self.n]
        self.n += 1
        return text[:60], text[60:80].strip()

    def numbers(self, data: str, kind, count: int, label: str, line: int | None = None):
        try:
            vals = [kind(x) for x in data.split()]
        except ValueError:
            vals = []
        if len(vals) < count:
            raise self.error(f"{label!r}: expected {count} numbers, got {data.strip()!r}", line)
        return vals[:count]

    def epoch(self, data: str, label: str) -> datetime:
        y, mo, d, h, mi, s = self.numbers(data, int, 6, label)
        try:
            return datetime(y, mo, d, h, mi, s, tzinfo=timezone.utc)
        except ValueError as exc:
            raise self.error(f"{label!r}: not a valid epoch ({exc})") from None

    def parse(self) -> IonexMaps:
        head = self.header()
        g = {k: self.numbers(head[k][0].replace("-", " -"), float, 3, k, head[k][1])
             for k in ("HGT1 / HGT2 / DHGT", "LAT1 / LAT2 / DLAT", "LON1 / LON2 / DLON")}
        dim = self.integer(head, "MAP DIMENSION", 2)
        h1, h2, _ = g["HGT1 / HGT2 / DHGT"]
        if dim != 2 or h1 != h2:
            raise self.error(f"only 2-D maps (one shell height) are supported, got MAP DIMENSION {dim}, "
                             f"heights {h1:g}..{h2:g} km", head.get("MAP DIMENSION", head["HGT1 / HGT2 / DHGT"])[1])
        lats, lons = (self.axis(head, name, *g[name]) for name in ("LAT1 / LAT2 / DLAT", "LON1 / LON2 / DLON"))
        expo, n_maps = self.integer(head, "EXPONENT", -1), self.integer(head, "# OF MAPS IN FILE", None)
        radius = self.numbers(head["BASE RADIUS"][0], float, 1, "BASE RADIUS", head["BASE RADIUS"][1])[0]
        mapping = head["MAPPING FUNCTION"][0].strip() if "MAPPING FUNCTION" in head else "COSZ"
        end_of_header, self.n = self.n, head["EPOCH OF FIRST MAP"][1]  # errors in the epoch name its line
        first = self.epoch(head["EPOCH OF FIRST MAP"][0], "EPOCH OF FIRST MAP")
        self.n = end_of_header
        epochs, maps = [], []
        while True:
            data, label = self.next("a map or 'END OF FILE'")
            if label == "END OF FILE":
                break
            if label == "START OF TEC MAP":
                epochs.append(self.tec_map(maps, lats, lons, expo, h1))
            elif label in ("START OF RMS MAP", "START OF HEIGHT MAP"):
                self.skip(label.replace("START", "END"))
            elif label or data.strip():
                raise self.error(f"expected 'START OF TEC MAP', 'START OF RMS MAP' or 'END OF FILE', got {label!r}")
        if not maps:
            raise self.error("no TEC map in the file")
        if len(maps) != n_maps:
            raise self.error(f"'# OF MAPS IN FILE' says {n_maps}, the file holds {len(maps)} TEC maps",
                             head["# OF MAPS IN FILE"][1])
        t = np.array([(e - first).total_seconds() for e in epochs])
        if np.any(np.diff(t) <= 0) or t[0] < 0:
            raise self.error("TEC map epochs must increase from 'EPOCH OF FIRST MAP'")
        week, sow = gpstime.utc_to_gps(first)
        tec = np.array(maps)
        lat_order, lon_order = np.argsort(lats), np.argsort(lons)
        return IonexMaps(path=str(self.path), first_week=week, first_sow=sow, t_s=t, lat_deg=lats[lat_order],
                         lon_deg=lons[lon_order], tec_tecu=tec[:, lat_order][:, :, lon_order], height_m=h1 * 1e3,
                         base_radius_m=radius * 1e3, mapping_function=mapping)

    def header(self) -> dict:
        """Header label -> (data columns, line number) after checking the version line and the needed labels."""
        data, label = self.next("'IONEX VERSION / TYPE'")
        if label != "IONEX VERSION / TYPE":
            raise self.error(f"expected the first line labelled 'IONEX VERSION / TYPE', got {label!r}")
        try:
            version = float(data[:8])
        except ValueError:
            raise self.error(f"unreadable IONEX version {data[:8].strip()!r}") from None
        if not 1.0 <= version < 2.0:
            raise self.error(f"IONEX version {version:g} is not supported (expected 1.x)")
        head = {}
        while True:
            data, label = self.next("'END OF HEADER'")
            if label == "END OF HEADER":
                break
            head.setdefault(label, (data, self.n))
        for need in ("EPOCH OF FIRST MAP", "# OF MAPS IN FILE", "BASE RADIUS", "HGT1 / HGT2 / DHGT",
                     "LAT1 / LAT2 / DLAT", "LON1 / LON2 / DLON"):
            if need not in head:
                raise self.error(f"header has no {need!r} line")
        return head

    def integer(self, head: dict, label: str, default):
        if label not in head:
            return default
        return int(self.numbers(head[label][0], int, 1, label, head[label][1])[0])

    def axis(self, head: dict, name: str, a: float, b: float, d: float) -> np.ndarray:
        """Grid values a, a + d, ..., b of header line ``name``."""
        if d == 0 or (b - a) / d < 1 or abs((b - a) / d - round((b - a) / d)) > 1e-6:
            raise self.error(f"{name!r}: expected a grid with a whole number (>= 1) of steps, got {a:g} {b:g} {d:g}",
                             head[name][1])
        return a + d * np.arange(int(round((b - a) / d)) + 1)

    def skip(self, end_label: str) -> None:
        while True:
            _, label = self.next(repr(end_label))
            if label == end_label:
                return

    def tec_map(self, maps, lats, lons, expo, height) -> datetime:
        start = self.n
        data, label = self.next("'EPOCH OF CURRENT MAP'")
        if label != "EPOCH OF CURRENT MAP":
            raise self.error(f"expected 'EPOCH OF CURRENT MAP' after 'START OF TEC MAP', got {label!r}")
        epoch = self.epoch(data, label)
        grid = np.full((lats.size, lons.size), np.nan)
        seen = np.zeros(lats.size, dtype=bool)
        per_row = -(-lons.size // 16)
        while True:
            data, label = self.next("'END OF TEC MAP'")
            if label == "END OF TEC MAP":
                break
            if label != "LAT/LON1/LON2/DLON/H":
                raise self.error(f"expected 'LAT/LON1/LON2/DLON/H' or 'END OF TEC MAP', got {label!r}")
            lat, lo1, lo2, dlo, h = self.numbers(data.replace("-", " -"), float, 5, label)
            row = np.flatnonzero(np.abs(lats - lat) < 1e-6)
            if row.size != 1 or abs(lo1 - lons[0]) > 1e-6 or abs(lo2 - lons[-1]) > 1e-6 or abs(h - height) > 1e-6:
                raise self.error(f"row {lat:g} {lo1:g} {lo2:g} {dlo:g} {h:g} is not on the header's grid")
            values = []
            for _ in range(per_row):
                text, lab = self.next(f"{lons.size} TEC values for latitude {lat:g}")
                if lab in _MAP_LABELS:     # a data line's columns 61-80 hold values, not a label
                    raise self.error(f"latitude {lat:g}: expected {lons.size} TEC values, got {len(values)} "
                                     f"before the line labelled {lab!r}")
                line = self.lines[self.n - 1]
                for c in range(0, len(line.rstrip()), 5):
                    field = line[c:c + 5].strip()
                    if field:
                        try:
                            values.append(int(field))
                        except ValueError:
                            raise self.error(f"expected integer TEC values (16I5), got {field!r}") from None
            if len(values) != lons.size:
                raise self.error(f"latitude {lat:g}: expected {lons.size} TEC values, got {len(values)}")
            v = np.array(values, dtype=float)
            grid[row[0]] = np.where(v == _MISSING, np.nan, v * 10.0 ** expo)
            seen[row[0]] = True
        if not seen.all():
            raise self.error(f"TEC map starting on line {start} lacks latitude {lats[~seen][0]:g}", start)
        maps.append(grid)
        return epoch
