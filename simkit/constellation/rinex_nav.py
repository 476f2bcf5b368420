"""RINEX 2.1x / 3.0x / 4.00 navigation files -> broadcast ephemeris constellation (GPS LNAV, BDS D1/D2, Galileo
I/NAV and F/NAV, QZSS LNAV, GLONASS FDMA state vectors).

RINEX 2 files hold one system each: GPS ('N: GPS NAV DATA', the IGS ``brdcDDD0.YYn`` files) or GLONASS ('G'); their
body is rewritten line for line in the RINEX 3 layout (satellite id with its letter, four-digit year, values one
column to the right) and read as RINEX 3, so line numbers in errors are the file's own. Two-digit years 80-99 are
19xx, 00-79 20xx (RINEX 2.11 section 6.10); the header's ION ALPHA / ION BETA give the GPS Klobuchar coefficients
and DELTA-UTC the GPS-UTC offset.

Mixed multi-GNSS files are accepted; GPS, BDS, Galileo, QZSS and GLONASS records are kept (SBAS and NavIC are
skipped), or only the systems named in ``systems``. Galileo: I/NAV and F/NAV records are both read; a satellite's
orbit and clock come from its I/NAV records (clock referred to E1/E5b, as RTKLIB's default), from F/NAV only when it
has no I/NAV record; BGD(E1,E5a) and BGD(E1,E5b) come from the same records. Galileo and QZSS toe/toc are in GST
and QZSST, which RINEX aligns with GPS weeks and GPST (their broadcast offsets to GPST, a few ns, are left out, as
RTKLIB does for orbits). GLONASS epochs are UTC and become GPS time with the leap seconds at that instant
(:mod:`.glonass`).
Satellite ids may be written "C03" or "C 3". RINEX 4 ``> EPH`` records of type LNAV (GPS) and D1/D2 (BDS) are
used for orbits; BDS CNV1/CNV2 records are read only for their group delays (TGD_B1Cp, TGD_B2ap, ISC_B1Cd,
ISC_B2ad); GPS CNAV/CNV2 and BDS CNV3 records are skipped. Klobuchar coefficients come from the RINEX 3 header
(GPSA/GPSB, BDSA/BDSB) or the first RINEX 4 ``> ION`` record of each system (G LNAV, C D1D2).

Time conventions of the file: GPS epochs and toe in GPST; BDS epochs, toe and week in BDT (converted here to
GPS-time seconds with BDT = GPST - 14 s, week + 1356). As in RTKLIB, a toe whose week disagrees with toc by
more than half a week is moved by one week.

The parser is hand-written and vectorised over records (fixed-width fields sliced from the byte lines at once)
because it is much faster than georinex on the same files (figure in docs/benchmarks.md).
"""
from __future__ import annotations

from datetime import date, timedelta

import numpy as np

from .. import gpstime
from ..errors import DataFileError
from . import kepler
from . import glonass
from .model import CombinedConstellation, GroupDelays, KeplerConstellation, Klobuchar, Records, TimeOffset
from .systems import GEO_MAX_INC_RAD, GEO_MIN_A_M, SYSTEMS

KEPLER_SYSTEMS = "GCEJ"
ALL_SYSTEMS = "GCEJR"
from .textfile import lines_of, number, read_bytes

N_FIELDS = 31  # af0 af1 af2 + 7 lines x 4 broadcast-orbit values
SECONDS_PER_WEEK = gpstime.SECONDS_PER_WEEK
# positions within the 31 values (RINEX 3.04 Tables A6 and A14; RINEX 4.00 LNAV/D1/D2 are identical)
AF0, AF1, AF2, IODE, CRS, DN, M0, CUC, E, CUS, SQRTA, TOE, CIC, OMEGA0, CIS, I0, CRC, OMEGA, OMEGADOT, IDOT, \
    CODES, WEEK, L2P, ACC, HEALTH, TGD1, TGD2 = range(27)
_REQUIRED = {SQRTA: "sqrt(A)", E: "eccentricity", I0: "i0", OMEGA0: "OMEGA0", TOE: "toe", WEEK: "week", M0: "M0"}
# lines per RINEX 3 record by system (GLONASS gained a line in 3.05); other letters are not checked
_RINEX3_LINES = {"G": (8,), "C": (8,), "E": (8,), "J": (8,), "I": (8,), "R": (4, 5), "S": (4,)}
_CNV_DELAYS = {"CNV1": {24: "ISC_B1Cd", 26: "TGD_B1Cp", 27: "TGD_B2ap"},
               "CNV2": {25: "ISC_B2ad", 26: "TGD_B1Cp", 27: "TGD_B2ap"}}


def is_rinex_nav(lines: list[str]) -> bool:
    """True when the first line is a RINEX navigation 'RINEX VERSION / TYPE' header (any version; RINEX 2
    GLONASS files are type 'G')."""
    if not lines or "RINEX VERSION / TYPE" not in lines[0]:
        return False
    kind = lines[0][20:21]
    return kind == "N" or kind == "G" and lines[0][:9].strip().startswith("2")


def _sat_id(text: str) -> str:
    """'C 3' / 'C03' / 'G 5' -> 'C03' / 'G05'."""
    return f"{text[0]}{int(text[1:3]):02d}"


def _epoch_seconds(text: str, path, line: int) -> float:
    """'2026 04 27 00 00 00' -> seconds since 1980-01-06 00:00 in the same time scale (calendar arithmetic)."""
    try:
        y, mo, d, h, mi = (int(v) for v in text[:16].split())
        sec = float(text[16:19])
        day = date(y, mo, d).toordinal() - gpstime.GPS_EPOCH_ORDINAL
    except ValueError:
        raise DataFileError(path, f"bad epoch {text.strip()!r}: expected 'YYYY MM DD hh mm ss'", line) from None
    return day * gpstime.SECONDS_PER_DAY + h * 3600.0 + mi * 60.0 + sec


def _values(block: list[str], path, first_line: int) -> np.ndarray:
    """The 31 numbers of one GPS/BDS record: af0..af2 from the epoch line, 4 per broadcast-orbit line."""
    vals = np.zeros(N_FIELDS)
    epoch = block[0]
    for k in range(3):
        vals[k] = number(epoch[23 + 19 * k: 42 + 19 * k], path, first_line, f"clock term {k}")
    for j, line in enumerate(block[1:8]):
        if line[:4].strip():
            raise DataFileError(path, "record is truncated: expected a broadcast-orbit line", first_line + 1 + j)
        for k in range(4):
            f = 3 + 4 * j + k
            vals[f] = number(line[4 + 19 * k: 23 + 19 * k], path, first_line + 1 + j, f"orbit value {f - 2}",
                             blank=None if f in _REQUIRED else 0.0)
    return vals


def _header(lines, path):
    """-> (index of the first data line, version, klobuchar dict)."""
    if not is_rinex_nav(lines):
        raise DataFileError(path, "not a RINEX navigation file (no 'RINEX VERSION / TYPE' with type N, or G for RINEX 2 "
                            "GLONASS)", 1)
    version = number(lines[0][:9], path, 1, "RINEX version", blank=None)
    if not 2.0 <= version < 5.0:
        raise DataFileError(path, f"RINEX navigation version {version} is not supported (2.1x, 3.0x or 4.0x)", 1)
    klob = {}
    for i, line in enumerate(lines):
        label = line[60:].strip()
        if label == "END OF HEADER":
            return i + 1, version, klob
        if version < 3.0 and label in ("ION ALPHA", "ION BETA"):
            vals = np.array([number(line[2 + 12 * k: 14 + 12 * k], path, i + 1, f"{label} coefficient {k}",
                                    blank=None) for k in range(4)])
            entry = klob.setdefault("G", Klobuchar(np.full(4, np.nan), np.full(4, np.nan)))
            setattr(entry, "alpha" if label == "ION ALPHA" else "beta", vals)
        if version < 3.0 and label == "DELTA-UTC: A0,A1,T,W":
            klob.setdefault("_sto", {})["GPUT"] = TimeOffset(
                "GPUT", number(line[3:22], path, i + 1, "A0", blank=None),
                number(line[22:41], path, i + 1, "A1", blank=None),
                (int(number(line[50:59], path, i + 1, "reference week W", blank=None)),
                 number(line[41:50], path, i + 1, "reference time T", blank=None)))
        if label == "TIME SYSTEM CORR" and line[:4].strip():
            klob.setdefault("_sto", {}).setdefault(line[:4], TimeOffset(
                line[:4], number(line[5:22], path, i + 1, "a0"), number(line[22:38], path, i + 1, "a1"),
                (int(number(line[45:50], path, i + 1, "reference week")),
                 number(line[38:45], path, i + 1, "reference time"))))
        if label == "IONOSPHERIC CORR" and line[:4] in ("GPSA", "GPSB", "BDSA", "BDSB"):
            vals = np.array([number(line[5 + 12 * k: 17 + 12 * k], path, i + 1, "ionospheric coefficient")
                             for k in range(4)])
            sys = "G" if line[:3] == "GPS" else "C"
            entry = klob.setdefault(sys, Klobuchar(np.full(4, np.nan), np.full(4, np.nan)))
            setattr(entry, "alpha" if line[3] == "A" else "beta", vals)
    raise DataFileError(path, "no 'END OF HEADER' line: truncated header", len(lines))


def _rinex3_records(buf: np.ndarray, nl: np.ndarray, start: int, lines_total: int, path, systems=ALL_SYSTEMS):
    """Vectorised RINEX 3 body reader on the raw bytes ``buf`` (uint8) with newline offsets ``nl``.

    Checks every record's line count, then returns (0-based line numbers of the Keplerian record starts of
    ``systems``, (R, 31) values, 0-based line numbers of the GLONASS record starts when 'R' is in ``systems``).
    ``start`` is the first body line. A bad field makes the per-record reader name its line.
    """
    line_start = np.concatenate(([0], nl + 1))[: nl.size + 1]
    line_end = np.append(nl, buf.size)
    end = lines_total
    first = np.where(line_end > line_start, buf[np.minimum(line_start, buf.size - 1)], 32)
    first = np.where(np.isin(first, (10, 13)), 32, first)
    blank_line = line_end - line_start == 0
    while end > start and (blank_line[end - 1] or first[end - 1] == 32 and _is_blank(buf, line_start[end - 1],
                                                                                      line_end[end - 1])):
        end -= 1
    body_first = first[start:end]
    starts = np.flatnonzero(body_first != 32)
    if end > start and (starts.size == 0 or starts[0] != 0):
        raise DataFileError(path, "expected a record start (satellite id in column 1)", start + 1)
    lengths = np.diff(np.append(starts, end - start))
    sys = body_first[starts]
    for code, allowed in _RINEX3_LINES.items():
        bad = (sys == ord(code)) & ~np.isin(lengths, allowed)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            i = start + starts[k]
            sat = bytes(buf[line_start[i]:line_start[i] + 3]).decode("latin-1").strip()
            raise DataFileError(path, f"record for {sat} starting here has {lengths[k]} lines, "
                                f"expected {' or '.join(map(str, allowed))} (truncated or malformed)", i + 1)
    kepler_sys = np.isin(sys, [ord(c) for c in KEPLER_SYSTEMS if c in systems])
    rec = start + starts[kepler_sys]
    glo = start + starts[sys == ord("R")] if "R" in systems else np.zeros(0, np.int64)
    if rec.size == 0:
        return rec, np.zeros((0, N_FIELDS)), glo
    rows = rec[:, None] + _SLOT_LINE[None, :]  # (R, 31) line numbers
    col0 = line_start[rows] + _SLOT_COL[None, :]
    pos = col0[..., None] + np.arange(19)  # (R, 31, 19) byte offsets
    inside = pos < line_end[rows][..., None]
    chars = np.where(inside, buf[np.minimum(pos, buf.size - 1)], 32).astype(np.uint8)
    chars[(chars == ord("D")) | (chars == ord("d"))] = ord("E")
    chars[chars == 13] = 32
    blank = (chars == 32).all(axis=-1)
    chars[blank, :3] = np.frombuffer(b"nan", np.uint8)
    try:
        vals = chars.reshape(-1, 19).view("S19").ravel().astype(float).reshape(rec.size, N_FIELDS)
    except ValueError:
        vals = None
    if vals is None or (blank & _REQUIRED_MASK).any():
        text = bytes(buf).decode("latin-1").splitlines()
        for i in rec:  # raises with the line of the first bad field
            _values(text[i:i + 8], path, i + 1)
    vals[blank] = 0.0
    return rec, vals, glo


def _is_blank(buf, a, b) -> bool:
    return not bytes(buf[a:b]).strip()


# (line within the record, first column) of the 31 values of a GPS/BDS record
_SLOTS = [(0, 23), (0, 42), (0, 61)] + [(j, 4 + 19 * k) for j in range(1, 8) for k in range(4)]
_SLOT_LINE = np.array([j for j, _ in _SLOTS])
_SLOT_COL = np.array([c for _, c in _SLOTS])
_REQUIRED_MASK = np.isin(np.arange(N_FIELDS), list(_REQUIRED))


def _rinex4_blocks(lines, start, path):
    """Yield (first line number, kind, block lines) for every RINEX 4 record (EPH, ION, ...)."""
    n = len(lines)
    i = start
    while i < n:
        line = lines[i]
        if not line.strip():
            i += 1
            continue
        if line[0] != ">":
            raise DataFileError(path, "expected a RINEX 4 record header starting with '>'", i + 1)
        j = i + 1
        while j < n and not lines[j].startswith(">"):
            j += 1
        yield i + 1, line, lines[i + 1:j]
        i = j


def read(path, raw: bytes | None = None, systems: str | None = None):
    """Parse a RINEX 3.0x/4.00 navigation file (plain or gzip; or its already-read content ``raw``) into a
    broadcast-ephemeris constellation: a :class:`KeplerConstellation`, or a :class:`CombinedConstellation`
    (Keplerian part first, GLONASS part last) when GLONASS records are kept. ``systems``: the RINEX letters to
    keep (default all of G, C, E, J, R)."""
    systems = ALL_SYSTEMS if systems is None else "".join(c for c in systems if c in ALL_SYSTEMS)
    raw = read_bytes(path) if raw is None else raw
    head_end = raw.find(b"END OF HEADER")
    head_end = len(raw) if head_end < 0 else raw.find(b"\n", head_end) + 1 or len(raw)
    head = lines_of(raw[:head_end]) + [""]
    start, version, klob = _header(head, path)
    if version < 3.0:
        raw = _rinex2_as_rinex3(raw, start, "R" if head[0][20:21] == "G" else "G", path)
    body = _rinex3_body if version < 4.0 else _rinex4_body
    ids, vals, delays, fnav, glo = body(raw, start, path, systems, klob)
    offsets = klob.pop("_sto", {})
    const = _assemble(path, klob, ids, vals, delays, fnav, glo, systems)
    const.time_offsets = offsets
    return const


def _rinex2_as_rinex3(raw: bytes, start: int, letter: str, path) -> bytes:
    """A RINEX 2 GPS (``letter`` 'G') or GLONASS ('R') navigation file with its body rewritten in the RINEX 3
    layout, line for line: a record's first line 'PP YY MM DD HH MM SS.S' + 3 values becomes 'GPP YYYY MM DD HH MM
    SS' + the same values; an orbit line (3 blanks, 4 values) gains a leading blank."""
    lines = raw.decode("latin-1").splitlines()
    out = lines[:start]
    for i in range(start, len(lines)):
        line = lines[i]
        if not line.strip() or not line[:3].strip():
            out.append(" " + line if line.strip() else line)
            continue
        try:
            prn = int(line[0:2])
            yy, mo, dd, hh, mi = (int(line[2 + 3 * k: 5 + 3 * k]) for k in range(5))
            sec = float(line[17:22])
        except ValueError:
            raise DataFileError(path, f"bad record start {line[:22].strip()!r}: expected the RINEX 2 satellite "
                                "number and epoch 'PP YY MM DD HH MM SS.S'", i + 1) from None
        if sec != int(sec):
            raise DataFileError(path, f"clock epoch seconds {sec} are not whole: not a broadcast record", i + 1)
        year = yy + (1900 if yy >= 80 else 2000)
        out.append(f"{letter}{prn:02d} {year:04d} {mo:02d} {dd:02d} {hh:02d} {mi:02d} {int(sec):02d}{line[22:]}")
    return ("\n".join(out) + "\n").encode("latin-1")


def _assemble(path, klob, ids, vals, delays, fnav, glo, systems):
    """The constellation object from the parsed records: Keplerian, GLONASS, or both combined."""
    if not ids and not glo:
        wanted = ", ".join(SYSTEM_NAMES[c] for c in systems)
        raise DataFileError(path, f"no broadcast ephemeris records found for {wanted or 'any system'}")
    if not glo:
        return build(ids, np.array(vals), str(path), klob, delays, path, np.array(fnav, bool))
    glo_ids = [g[0] for g in glo]
    glo_t = np.array([g[1] for g in glo])
    ref_week = int(np.floor(glo_t.min() / SECONDS_PER_WEEK))
    if ids:
        kep = build(ids, np.array(vals), str(path), klob, delays, path, np.array(fnav, bool))
        ref_week = kep.ref_week
    glo_c = _build_glonass(glo_ids, glo_t, np.array([g[2] for g in glo]), np.array([g[3] for g in glo]),
                           np.array([g[4] for g in glo]), ref_week, str(path), path)
    if not ids:
        return glo_c
    return CombinedConstellation([kep, glo_c], str(path))


def _rinex3_body(raw, start, path, systems, klob):
    """RINEX 3 records -> (ids, values + toc rows, CNAV delays (none), F/NAV flags, GLONASS records)."""
    buf = np.frombuffer(raw, np.uint8)
    nl = np.flatnonzero(buf == 10)
    n_lines = nl.size + (1 if buf.size and buf[-1] != 10 else 0)
    rec, values, glo_rec = _rinex3_records(buf, nl, start, n_lines, path, systems)
    line_start = np.concatenate(([0], nl + 1))
    heads = [raw[a:a + 23].decode("latin-1") for a in line_start[rec]]
    ids = [_sat_id(h[:3]) for h in heads]
    toc = np.array([_epoch_seconds(h[4:23], path, i + 1) for h, i in zip(heads, rec)])
    vals = np.column_stack([values, toc]) if rec.size else []
    fnav = [id_[0] == "E" and int(v[CODES]) & 2 != 0 for id_, v in zip(ids, values)]
    glo = []
    if glo_rec.size:
        text = lines_of(raw)
        glo = [_glonass_record(text[i:i + 4], path, i + 1) for i in glo_rec]
    return ids, vals, [], fnav, glo


def _rinex4_body(raw, start, path, systems, klob):
    """RINEX 4 records -> (ids, values + toc rows, BDS CNAV group delays, F/NAV flags, GLONASS records); the
    first ION record of GPS LNAV / BDS D1D2 fills ``klob``."""
    ids, vals, delays, fnav, glo = [], [], [], [], []
    for ln, head, block in _rinex4_blocks(lines_of(raw), start, path):
        parts = head[1:].split()
        if len(parts) < 3:
            raise DataFileError(path, "record header should read '> TYPE SAT MESSAGE'", ln)
        rtype, sat, msg = parts[0], parts[1], parts[2]
        if sat[0] not in systems:
            continue
        if rtype == "ION" and sat[0] not in klob and (msg, sat[0]) in (("LNAV", "G"), ("D1D2", "C")):
            klob[sat[0]] = _ion4(block, path, ln + 1)
        elif rtype == "STO" and len(block) >= 2:
            kind = block[0][24:28]
            week, sow = gpstime.normalize(0, _epoch_seconds(block[0][4:23], path, ln + 1))
            klob.setdefault("_sto", {}).setdefault(kind, TimeOffset(
                kind, number(block[1][23:42], path, ln + 2, "a0"), number(block[1][42:61], path, ln + 2, "a1"),
                (int(week), float(sow))))
        elif rtype == "EPH" and (sat[0], msg) in _KEPLER_MESSAGES:
            _check_len(block, ln + 1, path)
            ids.append(_sat_id(block[0][:3]))
            fnav.append(msg == "FNAV")
            vals.append(np.append(_values(block, path, ln + 1), _epoch_seconds(block[0][4:23], path, ln + 1)))
        elif rtype == "EPH" and sat[0] == "R" and msg == "FDMA":
            if len(block) < 4:
                raise DataFileError(path, f"FDMA record for {sat} has {len(block)} lines, expected 5",
                                    ln + len(block))
            glo.append(_glonass_record(block[:4], path, ln + 1))
        elif rtype == "EPH" and msg in _CNV_DELAYS and sat[0] == "C":
            if len(block) < 8:
                raise DataFileError(path, f"{msg} record is truncated", ln + len(block))
            row = [number(block[7][4 + 19 * k: 23 + 19 * k], path, ln + 8, "group delay", blank=np.nan)
                   for k in range(4)]
            t = _epoch_seconds(block[0][4:23], path, ln + 1)
            delays.extend((name, _sat_id(block[0][:3]), t, row[f - 24]) for f, name in _CNV_DELAYS[msg].items())
    return ids, vals, delays, fnav, glo


SYSTEM_NAMES = {"G": "GPS", "C": "BDS", "E": "Galileo", "J": "QZSS", "R": "GLONASS"}
_KEPLER_MESSAGES = {("G", "LNAV"), ("C", "D1"), ("C", "D2"), ("E", "INAV"), ("E", "FNAV"), ("J", "LNAV")}


def _glonass_record(block, path, ln):
    """One GLONASS record (RINEX 3 or 4, first 4 lines) -> (sat id, tb GPS seconds since 1980, (9,) position,
    velocity and acceleration m, m/s, m/s^2 + (-tau_n -> tau_n, gamma_n) as (11,), health, channel)."""
    head = block[0]
    for j, line in enumerate(block[1:4]):
        if line[:4].strip():
            raise DataFileError(path, "GLONASS record is truncated: expected a broadcast-orbit line", ln + 1 + j)
    minus_tau = number(head[23:42], path, ln, "-TauN", blank=None)
    gamma = number(head[42:61], path, ln, "GammaN", blank=None)
    orbit = np.array([[number(block[1 + a][4 + 19 * k: 23 + 19 * k], path, ln + 1 + a,
                              f"GLONASS orbit value {4 * a + k + 1}", blank=None if k < 2 else 0.0)
                       for k in range(4)] for a in range(3)])  # rows x, y, z; columns pos km, vel, acc, extra
    channel = int(orbit[1, 3])
    if channel not in glonass.FREQ_CHANNELS:
        raise DataFileError(path, f"GLONASS frequency number {channel}: expected -7..13", ln + 2)
    utc_s = _epoch_seconds(head[4:23], path, ln)
    tb = utc_s + _leap_seconds_at(utc_s)
    state = np.concatenate([orbit[:, 0], orbit[:, 1], orbit[:, 2]]) * 1e3
    return _sat_id(head[:3]), tb, np.concatenate([state, [-minus_tau, gamma]]), orbit[0, 3] == 0, channel


def _leap_seconds_at(utc_seconds: float) -> float:
    """GPST - UTC (s) at UTC seconds since 1980-01-06 (skyfield's table)."""
    when = gpstime.GPS_EPOCH + timedelta(seconds=float(utc_seconds))
    return gpstime.leap_seconds(when) + gpstime.GPS_MINUS_TAI


def _build_glonass(ids, tb, values, healthy, channel, ref_week, source, path):
    sat_ids = sorted(set(ids))
    sat = np.searchsorted(sat_ids, ids)
    for s in range(len(sat_ids)):
        ks = np.unique(channel[sat == s])
        if ks.size > 1:
            raise DataFileError(path, f"{sat_ids[s]}: records give different frequency numbers "
                                f"{', '.join(map(str, ks))}")
    p = np.zeros((len(ids), glonass.N_COLS))
    p[:, glonass.TB] = tb - ref_week * SECONDS_PER_WEEK
    p[:, 1:10] = values[:, :9]
    p[:, glonass.TAUN], p[:, glonass.GAMN] = values[:, 9], values[:, 10]
    return glonass.GlonassConstellation(sat_ids, glonass.GlonassRecords(p, sat, healthy, channel), source,
                                        ref_week)


def _check_len(block, ln, path):
    if len(block) != 8:
        raise DataFileError(path, f"record for {block[0][:3].strip()} starting here has {len(block)} lines, "
                            "expected 8 (truncated or malformed)", ln)


def _ion4(block, path, ln) -> Klobuchar:
    vals = []
    for j, line in enumerate(block[:3]):
        lo = 23 if j == 0 else 4
        for k in range(3 if j == 0 else 4):
            vals.append(number(line[lo + 19 * k: lo + 19 + 19 * k], path, ln + j, "Klobuchar coefficient",
                               blank=np.nan))
    if len(vals) < 8:
        raise DataFileError(path, "ION record is truncated: expected 8 Klobuchar coefficients", ln)
    return Klobuchar(np.array(vals[:4]), np.array(vals[4:8]))


def build(ids, vals, source, klob, cnav_delays, path, fnav=None) -> KeplerConstellation:
    """Records (one row of 31 RINEX values + toc calendar seconds per record) -> KeplerConstellation.

    ``fnav`` (R,) bool marks Galileo F/NAV records: they are kept in the table but used for a satellite's states
    only when it has no I/NAV record."""
    ids = np.array(ids)
    sat_ids = sorted(set(ids.tolist()))
    sat = np.searchsorted(sat_ids, ids)
    letter = ids.astype("<U1")
    is_bds = letter == "C"
    offs = np.zeros(len(ids))
    week_off = np.zeros(len(ids), dtype=np.int64)
    half = np.zeros(len(ids))
    for code, system in SYSTEMS.items():
        m = letter == code
        offs[m], week_off[m], half[m] = system.time_offset_s, system.week_offset, system.fit_half_s
    toc_abs = vals[:, N_FIELDS] + offs
    toe_abs = (vals[:, WEEK] + week_off) * SECONDS_PER_WEEK + vals[:, TOE] + offs
    toe_abs += SECONDS_PER_WEEK * np.round((toc_abs - toe_abs) / SECONDS_PER_WEEK)
    ref_week = int(np.floor(toe_abs.min() / SECONDS_PER_WEEK))
    t0 = ref_week * SECONDS_PER_WEEK
    n = len(ids)
    p = kepler.empty_table(n)
    c = kepler.COL
    p[:, c["toe"]] = toe_abs - t0
    p[:, c["toc"]] = toc_abs - t0
    for name, f in (("sqrt_a", SQRTA), ("e", E), ("i0", I0), ("omega0", OMEGA0), ("omega", OMEGA), ("m0", M0),
                    ("delta_n", DN), ("idot", IDOT), ("omega_dot", OMEGADOT), ("cuc", CUC), ("cus", CUS),
                    ("crc", CRC), ("crs", CRS), ("cic", CIC), ("cis", CIS), ("af0", AF0), ("af1", AF1),
                    ("af2", AF2), ("toe_sow", TOE)):
        p[:, c[name]] = vals[:, f]
    for code, system in SYSTEMS.items():
        m = letter == code
        p[m, c["mu"]] = system.mu
        p[m, c["omega_e"]] = system.omega_e
        p[m, c["rel_f"]] = system.rel_f
    bad = (vals[:, SQRTA] <= 0) | (vals[:, E] < 0) | (vals[:, E] >= 1)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise DataFileError(path, f"record {k + 1} ({ids[k]}): sqrt(A) must be > 0 and 0 <= e < 1")
    p[:, c["geo"]] = is_bds & (vals[:, SQRTA] ** 2 > GEO_MIN_A_M) & (np.abs(vals[:, I0]) < GEO_MAX_INC_RAD)
    use = vals[:, HEALTH] == 0
    if fnav is not None and fnav.any():
        has_inav = np.zeros(len(sat_ids), bool)
        has_inav[sat[~fnav & (letter == "E")]] = True
        use &= ~(fnav & has_inav[sat])
    records = Records(p, sat, use, half, after_toe=letter == "E")
    delays = {}
    is_gal = letter == "E"
    for name, f, m in (("TGD", TGD1, (letter == "G") | (letter == "J")), ("TGD1", TGD1, is_bds),
                       ("TGD2", TGD2, is_bds), ("BGD_E5a", TGD1, is_gal & use), ("BGD_E5b", TGD2, is_gal & use)):
        if m.any():
            delays[name] = GroupDelays(sat[m], p[m, c["toe"]], vals[m, f])
    for name in sorted({d[0] for d in cnav_delays}):
        rows = [d for d in cnav_delays if d[0] == name and d[1] in sat_ids]
        if rows:
            delays[name] = GroupDelays(np.searchsorted(sat_ids, [r[1] for r in rows]),
                                       np.array([r[2] for r in rows]) + SYSTEMS["C"].time_offset_s - t0,
                                       np.array([r[3] for r in rows]))
    return KeplerConstellation(sat_ids, records, source, ref_week, "broadcast", klob, delays)
