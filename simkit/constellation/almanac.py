"""GPS YUMA and SEM almanacs, and almanacs derived from broadcast ephemerides (e.g. for BDS, which has no public
text almanac).

Almanac model (IS-GPS-200 20.3.3.5.2.3 / Table 20-VI): Keplerian orbit from sqrt(A), e, i, Omega_0, OMEGA_DOT,
omega, M_0 at t_oa, with the GPS constants, no harmonic corrections; clock af0 + af1 (t - t_oa) plus the
relativistic term. SEM gives angles in semicircles and the inclination as an offset from 0.30 semicircles.
Almanac weeks are 10-bit: a record repeats every 1024 weeks and each query uses the copy nearest to it, so no
rollover guess is needed. States are returned within ``validity_days`` (default 7) of t_oa, NaN outside.
"""
from __future__ import annotations


import numpy as np

from .. import gpstime
from ..errors import DataFileError
from . import kepler
from .model import KeplerConstellation, Records
from .systems import GPS
from .textfile import number

ROLLOVER_S = gpstime.ALMANAC_ROLLOVER_WEEKS * gpstime.SECONDS_PER_WEEK
DEFAULT_VALIDITY_DAYS = 7.0
_YUMA_KEYS = {  # label prefix (lower case) -> field
    "id": "prn", "health": "health", "eccentricity": "e", "time of applicability": "toa",
    "orbital inclination": "i0", "rate of right ascen": "omega_dot", "sqrt(a)": "sqrt_a",
    "right ascen at week": "omega0", "argument of perigee": "omega", "mean anom": "m0", "af0": "af0",
    "af1": "af1", "week": "week",
}


def is_yuma(lines) -> bool:
    return any("almanac for prn" in ln.lower() for ln in lines[:5])


def is_sem(lines) -> bool:
    head = [ln.split() for ln in lines[:2]]
    return (len(head) == 2 and len(head[0]) >= 1 and head[0][0].isdigit() and len(head[1]) == 2
            and all(tok.isdigit() for tok in head[1]))


def _kepler_rows(rows, path):
    """rows: dicts with prn, health, e, toa, week, i0, omega_dot, sqrt_a, omega0, omega, m0, af0, af1 -> table."""
    p = kepler.empty_table(len(rows))
    c = kepler.COL
    for k, r in enumerate(rows):
        if not (r["sqrt_a"] > 0 and 0 <= r["e"] < 1):
            raise DataFileError(path, f"PRN {r['prn']}: sqrt(A) must be > 0 and 0 <= e < 1", r["line"])
        t = r["week"] * gpstime.SECONDS_PER_WEEK + r["toa"]
        p[k, c["toe"]] = p[k, c["toc"]] = t
        p[k, c["toe_sow"]] = r["toa"]
        for name in ("sqrt_a", "e", "i0", "omega0", "omega", "m0", "omega_dot", "af0", "af1"):
            p[k, c[name]] = r[name]
        p[k, c["mu"]], p[k, c["omega_e"]], p[k, c["rel_f"]] = GPS.mu, GPS.omega_e, GPS.rel_f
    return p


def _constellation(rows, path, kind, validity_days):
    rows = sorted(rows, key=lambda r: r["prn"])
    prns = [r["prn"] for r in rows]
    dup = {p for p in prns if prns.count(p) > 1}
    if dup:
        raise DataFileError(path, f"PRN {min(dup)} appears more than once")
    if not rows:
        raise DataFileError(path, "no almanac records found")
    p = _kepler_rows(rows, path)
    n = len(rows)
    records = Records(p, np.arange(n), np.array([r["health"] == 0 for r in rows]),
                      np.full(n, validity_days * gpstime.SECONDS_PER_DAY), np.full(n, ROLLOVER_S))
    return KeplerConstellation([f"G{r['prn']:02d}" for r in rows], records, str(path), 0, kind)


def read_yuma(path, lines, validity_days: float = DEFAULT_VALIDITY_DAYS) -> KeplerConstellation:
    """Parse a YUMA almanac (text lines) into a constellation."""
    rows, cur = [], None
    for i, line in enumerate(lines, 1):
        if "almanac for prn" in line.lower():
            if cur is not None:
                rows.append(_finish_yuma(cur, path))
            cur = {"line": i, "_last": i}
            continue
        if not line.strip():
            continue
        if cur is None or ":" not in line:
            raise DataFileError(path, "expected 'label: value' inside a YUMA record", i)
        label, value = line.split(":", 1)
        key = next((f for k, f in _YUMA_KEYS.items() if label.strip().lower().startswith(k)), None)
        if key is None:
            raise DataFileError(path, f"unknown YUMA label {label.strip()!r}", i)
        cur[key] = number(value, path, i, label.strip(), blank=None)
        cur["_last"] = i
    if cur is not None:
        rows.append(_finish_yuma(cur, path))
    return _constellation(rows, path, "almanac", validity_days)


def _finish_yuma(cur, path):
    missing = [f for f in _YUMA_KEYS.values() if f not in cur]
    if missing:
        raise DataFileError(path, f"YUMA record starting at line {cur['line']} is missing {', '.join(missing)} "
                            "(truncated?)", cur["_last"])
    cur["prn"] = int(cur["prn"])
    return cur


def read_sem(path, lines, validity_days: float = DEFAULT_VALIDITY_DAYS) -> KeplerConstellation:
    """Parse a SEM almanac (text lines): header 'count name' / 'week toa', then 14 values per record."""
    count = int(lines[0].split()[0])
    week, toa = (int(v) for v in lines[1].split())
    tokens = [(tok, i) for i, ln in enumerate(lines[2:], 3) for tok in ln.split()]
    if len(tokens) != 14 * count:
        last = tokens[-1][1] if tokens else 2
        raise DataFileError(path, f"header announces {count} records (14 values each) but the file holds "
                            f"{len(tokens)} values (truncated or malformed)", last)
    pi = np.pi
    rows = []
    for k in range(count):
        v = [number(t, path, ln, "SEM value", blank=None) for t, ln in tokens[14 * k: 14 * k + 14]]
        rows.append({
            "line": tokens[14 * k][1], "prn": int(v[0]), "e": v[3], "i0": (0.30 + v[4]) * pi,
            "omega_dot": v[5] * pi, "sqrt_a": v[6], "omega0": v[7] * pi, "omega": v[8] * pi,
            "m0": v[9] * pi, "af0": v[10], "af1": v[11], "health": int(v[12]), "week": week, "toa": toa,
        })
        if not 1 <= rows[-1]["prn"] <= 32:
            raise DataFileError(path, f"PRN {v[0]:g} out of range 1-32", tokens[14 * k][1])
    return _constellation(rows, path, "almanac", validity_days)


def from_ephemeris(const: KeplerConstellation, gps_week: int, gps_sow: float,
                   validity_days: float = DEFAULT_VALIDITY_DAYS) -> KeplerConstellation:
    """Almanac derived from a broadcast ephemeris: for each satellite, its healthy record nearest to
    (gps_week, gps_sow), propagated with the almanac model (Keplerian with the record's own secular terms:
    mean-motion correction delta_n and OMEGA_DOT kept; harmonic corrections, IDOT and af2 dropped), valid
    ``validity_days`` either side. Satellites with no healthy record are left out."""
    t = gpstime.diff_seconds(gps_week, gps_sow, const.ref_week, 0.0)
    keep, rows = [], []
    c = kepler.COL
    toe = const.records.params[:, c["toe"]]
    for s, sid in enumerate(const.sat_ids):
        cand = np.flatnonzero((const.records.sat == s) & const.records.healthy)
        if cand.size:
            keep.append(sid)
            rows.append(cand[np.argmin(np.abs(toe[cand] - t))])
    if not rows:
        raise DataFileError(const.source, "no healthy broadcast record to derive an almanac from")
    p = const.records.params[rows].copy()
    p[:, [c[k] for k in ("cuc", "cus", "crc", "crs", "cic", "cis", "idot", "af2")]] = 0.0
    n = len(rows)
    records = Records(p, np.arange(n), np.ones(n, bool), np.full(n, validity_days * gpstime.SECONDS_PER_DAY))
    out = KeplerConstellation(keep, records, f"almanac from {const.source}", const.ref_week, "almanac")
    out.orbit_type = const.orbit_type[[const.sat_ids.index(s) for s in keep]]
    return out
