"""Reading RINEX observation files: versions 2.10/2.11, 3.0x and 4.00, plain, gzip or Hatanaka-compressed.

The result keeps the file's own content, per satellite system: every observation type as a (M, S_sys) array
(NaN where blank), its loss-of-lock indicator (LLI, RINEX bits 0-2) and signal-strength indicator (SSI 1-9, 0
blank). RINEX 2 two-character types are given their RINEX 3 names (C1 -> C1C, P1 -> C1W, L1 -> L1C, P2 -> C2W,
L2 -> L2W, C2 -> C2X in 2.11 and C2W from 2.12, C5/L5 -> C5X/L5X; GLONASS C1/L1 -> C1C/L1C, P1 -> C1P,
C2 -> C2C, P2 -> C2P, the G2 phase with the C/A code only when the file has no P2; RINEX 2.11 sec. 5.1 and the RINEX 3.04
table 4 correspondence). :func:`signal_name` maps a system and RINEX 3 code to a simkit signal through the
signal table of :mod:`.signals` (system, band digit, tracking attribute), so a signal added there is imported.

Epoch time tags are receiver time in the file's time system (RINEX 3.04 sec. 5.1); GPS (also for GAL, whose
system time is aligned with GPS) and BDT (converted, GPST = BDT + 14 s) are supported. Events that are not
observations are not errors but are reported (``notes``): epoch flags 2-5 and their special records (skipped),
flag 6 cycle-slip records (skipped), flag 1 power failures, and receiver clock offsets in epoch lines.
A malformed file is one :class:`~simkit.errors.DataFileError` naming the file, the line and what was expected.

Fixed-width fields of every satellite record are converted at once (NumPy byte slicing, as in
:mod:`simkit.constellation.rinex_nav`): only the epoch structure is walked line by line.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from datetime import date

import numpy as np

from .. import gpstime
from ..constellation.textfile import number, read_bytes
from ..errors import DataFileError, InputError
from . import signals as sigmod

FIELD = 16  # F14.3 value, LLI digit, SSI digit
SUPPORTED_TIME_SYSTEMS = {"GPS": 0.0, "GAL": 0.0, "BDT": -gpstime.BDT_MINUS_GPST}  # seconds to add for GPST

# RINEX 2 observation type -> RINEX 3 code for GPS (band digit and tracking attribute; sec. 5.1 of 2.11)
_V2_GPS = {"C1": "C1C", "P1": "C1W", "L1": "L1C", "D1": "D1C", "S1": "S1C", "P2": "C2W", "L2": "L2W",
           "D2": "D2W", "S2": "S2W", "C5": "C5X", "L5": "L5X", "D5": "D5X", "S5": "S5X"}
# and for GLONASS codes: C/A on G1 and G2, P code as P (RINEX 2.11 sec. 5.1)
_V2_GLO = {"C1": "C1C", "P1": "C1P", "C2": "C2C", "P2": "C2P"}


@dataclass(frozen=True)
class ObsHeader:
    """What the importer needs of a RINEX observation header. ``obs_types`` {system letter: [RINEX 3 codes]};
    ``approx_pos_ecef`` (3,) m or None; ``antenna_delta_hen`` (3,) m height, east, north of the antenna reference
    point above the marker; ``time_system`` 'GPS', 'GAL' or 'BDT'; ``interval_s`` or None; ``glonass_channels``
    each GLONASS satellite's FDMA frequency number k (-7..+13) where the header lists it."""

    version: float
    file_system: str
    marker: str
    receiver: str
    antenna: str
    approx_pos_ecef: np.ndarray | None
    antenna_delta_hen: np.ndarray
    obs_types: dict
    time_system: str
    interval_s: float | None
    clock_offset_applied: bool
    glonass_channels: dict = field(default_factory=dict)   # {"R03": k}: 'GLONASS SLOT / FRQ #' (RINEX >= 3.02)


@dataclass(frozen=True)
class SystemObs:
    """One system's observations: ``sats`` (S,) ids; ``types`` (T,) RINEX 3 codes; ``values`` (M, S, T) float
    (m, cycles, Hz, dB-Hz; NaN blank); ``lli`` and ``ssi`` (M, S, T) uint8 (0 blank)."""

    sats: list
    types: list
    values: np.ndarray
    lli: np.ndarray
    ssi: np.ndarray


@dataclass(frozen=True)
class ObsFile:
    """A parsed observation file: ``start`` (GPS week, sow) of the first epoch; ``t`` (M,) s of each epoch since
    it (receiver time tags converted to GPS time); ``systems`` {letter: :class:`SystemObs`}; ``clock_offset_s``
    (M,) receiver clock offsets of the epoch lines (NaN where none); ``notes`` [one-line remarks on events and
    skipped records]."""

    path: str
    header: ObsHeader
    start: tuple
    t: np.ndarray
    systems: dict
    clock_offset_s: np.ndarray
    notes: list = field(default_factory=list)


def decompress(path) -> bytes:
    """The RINEX text of ``path``: gunzipped when gzip data, expanded when Hatanaka (CRINEX) compressed."""
    raw = read_bytes(path)
    if raw[:80].find(b"COMPACT RINEX FORMAT") >= 0 or raw[:80].find(b"CRINEX VERS") >= 0:
        try:
            import hatanaka
        except ImportError:
            raise InputError(str(path), "is Hatanaka-compressed (CRINEX): install the 'hatanaka' package "
                                        "(pip install 'simkit[rinex]')") from None
        try:
            raw = hatanaka.decompress(raw)
        except Exception as exc:  # the package raises bare ValueErrors and its own errors on bad input
            raise DataFileError(path, f"Hatanaka decompression failed: {exc}") from None
        if isinstance(raw, str):
            raw = raw.encode("latin-1")
    return raw


KINDS = {"C": "code", "L": "carrier", "D": "doppler", "S": "cn0"}


def signal_name(system: str, code: str, version: float) -> str | None:
    """The simkit signal of RINEX 3 observation ``code`` (e.g. "C1C") of ``system`` ("G"), None when simkit has
    no such signal. BDS B1I written with band 1 (RINEX 3.02: C1I, C1Q; C1X before 3.03) is band 2 of 3.03 on."""
    band, attr = code[1:2], code[2:3]
    if system == "C" and band == "1" and (attr in ("I", "Q") or (attr == "X" and version < 3.03)):
        band = "2"
    for s in sigmod.SIGNALS.values():
        if s.system == system and s.rinex_band == band and s.rinex_attr == attr:
            return s.name
    return None


def _v2_code(sys: str, code: str, version: float, types=()) -> str:
    """A RINEX 2 observation type as a RINEX 3 code (``types`` all the file's types; systems other than GPS and
    GLONASS: the band digit and attribute X)."""
    if sys == "G":
        if code == "C2":
            return "C2W" if version >= 2.12 else "C2X"
        if code in _V2_GPS:
            return _V2_GPS[code]
    if sys == "R":
        if code in _V2_GLO:
            return _V2_GLO[code]
        if code[0] in "LDS" and code[1:] in ("1", "2"):
            # a P-code phase is a quarter cycle off the C/A one: C/A unless the band has a P code (on G1: and no C/A)
            b = code[1]
            return code + ("C" if f"P{b}" not in types or (b == "1" and "C1" in types) else "P")
    return code + "X" if len(code) == 2 else code


def read_header(lines, path):
    """-> (:class:`ObsHeader`, index of the first data line)."""
    if not lines or "RINEX VERSION / TYPE" not in lines[0]:
        raise DataFileError(path, "not a RINEX file: the first line should be 'RINEX VERSION / TYPE'", 1)
    first = lines[0]
    kind = first[20:21]
    if kind != "O":
        what = "a navigation file" if kind in "NGHLC" and kind.strip() else f"type {kind.strip() or 'blank'}"
        raise DataFileError(path, f"is {what}, expected a RINEX observation file (type 'O' in column 21)", 1)
    version = number(first[:9], path, 1, "RINEX version", None)
    if not (2.10 <= version < 2.2 or 3.0 <= version < 3.1 or 4.0 <= version < 4.1):
        raise DataFileError(path, f"RINEX version {version:g} is not supported (2.10, 2.11, 3.0x or 4.00)", 1)
    state = _HeaderState(path, version, first[40:41].strip() or "G")
    for i, line in enumerate(lines[1:], start=2):
        if line[60:80].strip() == "END OF HEADER":
            return state.finish(i), i
        state.read(line, i)
    raise DataFileError(path, "no 'END OF HEADER' line: truncated header", len(lines))


class _HeaderState:
    """The header records read so far."""

    def __init__(self, path, version, file_sys):
        self.path, self.version, self.file_sys = path, version, file_sys
        self.info = {"marker": "", "receiver": "", "antenna": "", "pos": None, "delta": np.zeros(3),
                     "interval": None, "tsys": "", "applied": False}
        self.types: dict[str, list[str]] = {}
        self.v2_types: list[str] = []
        self.n_v2 = None
        self.pending = None  # (system, announced count) of the RINEX 3 obs-types record being read
        self.channels: dict[str, int] = {}

    def _check_pending(self, i):
        if self.pending and len(self.types[self.pending[0]]) != self.pending[1]:
            raise DataFileError(self.path, f"'SYS / # / OBS TYPES' for {self.pending[0]} announces "
                                f"{self.pending[1]} types, lists {len(self.types[self.pending[0]])}", i)

    def read(self, line, i):
        label, info, path = line[60:80].strip(), self.info, self.path
        if label == "MARKER NAME":
            info["marker"] = line[:60].strip()
        elif label == "REC # / TYPE / VERS":
            info["receiver"] = line[20:40].strip()
        elif label == "ANT # / TYPE":
            info["antenna"] = line[20:40].strip()
        elif label == "APPROX POSITION XYZ":
            pos = np.array([number(line[14 * k:14 * k + 14], path, i, "APPROX POSITION XYZ coordinate", None)
                            for k in range(3)])
            info["pos"] = pos if np.linalg.norm(pos) > 0 else None  # 0,0,0 means unknown
        elif label == "ANTENNA: DELTA H/E/N":
            info["delta"] = np.array([number(line[14 * k:14 * k + 14], path, i, "antenna delta", 0.0)
                                      for k in range(3)])
        elif label == "INTERVAL":
            info["interval"] = number(line[:10], path, i, "INTERVAL", None)
        elif label == "TIME OF FIRST OBS":
            info["tsys"] = line[48:51].strip()
        elif label == "RCV CLOCK OFFS APPL":
            info["applied"] = number(line[:6], path, i, "RCV CLOCK OFFS APPL", 0.0) == 1
        elif label == "# / TYPES OF OBSERV" and self.version < 3:
            if line[:6].strip():
                self.n_v2 = int(number(line[:6], path, i, "number of observation types", None))
            elif self.n_v2 is None:
                raise DataFileError(path, "'# / TYPES OF OBSERV' continuation line before its first line", i)
            self.v2_types += line[6:60].split()
        elif label == "SYS / # / OBS TYPES" and self.version >= 3:
            self._obs_types(line, i)
        elif label == "GLONASS SLOT / FRQ #":
            self._glonass_slots(line, i)

    def _glonass_slots(self, line, i):
        """Up to eight 'Rnn kk' entries from column 5, seven characters each (RINEX 3.02+)."""
        for k in range(8):
            entry = line[4 + 7 * k:10 + 7 * k]
            if not entry.strip():
                continue
            sat, chan = entry[:3].replace(" ", "0"), entry[3:].strip()
            if not (sat[0] == "R" and sat[1:].isdigit()):
                raise DataFileError(self.path, f"'GLONASS SLOT / FRQ #': bad satellite {entry[:3]!r} (expected R01 "
                                    "..)", i)
            try:
                value = int(chan)
            except ValueError:
                value = None
            if value is None or not -7 <= value <= 13:
                raise DataFileError(self.path, f"'GLONASS SLOT / FRQ #': frequency number {chan!r} of {sat} "
                                    "(expected an integer -7 .. 13)", i)
            self.channels[sat] = value

    def _obs_types(self, line, i):
        sys = line[0:1]
        if sys.strip():
            self._check_pending(i)
            self.pending = (sys, int(number(line[3:6], self.path, i, "number of observation types", None)))
            self.types[sys] = []
        elif self.pending is None:
            raise DataFileError(self.path, "'SYS / # / OBS TYPES' continuation line before its first line", i)
        codes = line[7:58].split()
        bad = [c for c in codes if len(c) != 3]
        if bad:
            raise DataFileError(self.path, f"observation type {bad[0]!r}: expected 3 characters (e.g. C1C)", i)
        self.types[self.pending[0]] += codes

    def finish(self, i) -> ObsHeader:
        path, info = self.path, self.info
        if self.version < 3:
            if self.n_v2 is None:
                raise DataFileError(path, "missing '# / TYPES OF OBSERV' header record", i)
            if len(self.v2_types) != self.n_v2:
                raise DataFileError(path, f"'# / TYPES OF OBSERV' announces {self.n_v2} types, lists "
                                    f"{len(self.v2_types)}", i)
            systems = {"G", "R", "E", "S", "C", "J", "I"} if self.file_sys == "M" else {self.file_sys}
            self.types = {s: [_v2_code(s, c, self.version, self.v2_types) for c in self.v2_types]
                          for s in sorted(systems)}
        elif not self.types:
            raise DataFileError(path, "missing 'SYS / # / OBS TYPES' header record", i)
        self._check_pending(i)
        tsys = info["tsys"] or {"C": "BDT", "E": "GAL"}.get(self.file_sys, "GPS")
        if tsys not in SUPPORTED_TIME_SYSTEMS:
            raise DataFileError(path, f"time system {tsys!r} of 'TIME OF FIRST OBS' is not supported "
                                f"(expected {', '.join(SUPPORTED_TIME_SYSTEMS)})")
        return ObsHeader(self.version, self.file_sys, info["marker"], info["receiver"], info["antenna"],
                         info["pos"], info["delta"], self.types, tsys, info["interval"], info["applied"],
                         self.channels)


def _sat_id(text: str, path, line: int, default: str) -> str:
    sys = text[0] if text[0] != " " else default
    num = text[1:3].strip()
    if not (sys.isalpha() and num.isdigit()):
        raise DataFileError(path, f"bad satellite id {text!r}: expected a system letter and a number (G05, C 3)", line)
    return f"{sys}{int(num):02d}"


def _epoch_seconds(y, mo, d, h, mi, sec) -> tuple[int, float]:
    """(days since the GPS epoch, seconds of day): two numbers, so that differences keep sub-ns resolution."""
    return date(y, mo, d).toordinal() - gpstime.GPS_EPOCH_ORDINAL, h * 3600.0 + mi * 60.0 + sec


class _Walker:
    """The epoch structure of the data section: epoch times, flags and the satellite record lines."""

    def __init__(self, lines, start, hdr, path):
        self.lines, self.start, self.hdr, self.path = lines, start, hdr, path
        self.times, self.clocks = [], []
        self.records: list[tuple[int, str, int]] = []   # (epoch index, satellite id, first line index)
        self.notes = Counter()
        self.first_note: dict = {}

    def note(self, kind: str, line: int) -> None:
        self.notes[kind] += 1
        self.first_note.setdefault(kind, line)

    def walk(self):
        lines, n = self.lines, len(self.lines)
        i = self.start
        v3 = self.hdr.version >= 3
        while i < n:
            line = lines[i]
            if not line.strip():
                if v3:
                    raise DataFileError(self.path, "blank line where an epoch record ('>') was expected", i + 1)
                i += 1
                continue
            i = self._epoch3(i) if v3 else self._epoch2(i)

    def _epoch_fields(self, line, i, v3):
        try:
            if v3:
                y, mo, d, h, mi = int(line[2:6]), int(line[7:9]), int(line[10:12]), int(line[13:15]), int(line[16:18])
                sec, flag, count = float(line[18:29]), int(line[31:32]), int(line[32:35])
            else:
                yy = int(line[1:3])
                y = yy + (2000 if yy < 80 else 1900)
                mo, d, h, mi = int(line[4:6]), int(line[7:9]), int(line[10:12]), int(line[13:15])
                sec, flag, count = float(line[15:26]), int(line[28:29]), int(line[29:32])
            t = _epoch_seconds(y, mo, d, h, mi, sec)
        except ValueError:
            form = "'> YYYY MM DD hh mm ss.sssssss  F NNN'" if v3 else "' YY MM DD hh mm ss.sssssss  F NN'"
            raise DataFileError(self.path, f"bad or truncated epoch line {line.rstrip()!r}: expected {form}",
                                i + 1) from None
        if flag > 6:
            raise DataFileError(self.path, f"epoch flag {flag}: expected 0-6", i + 1)
        return t, flag, count

    def _clock(self, text, i):
        if not text.strip():
            return np.nan
        self.note("receiver clock offset in epoch lines", i + 1)
        return number(text, self.path, i + 1, "receiver clock offset", None)

    def _special(self, i, flag, count) -> int:
        """Skip the ``count`` special records of an event epoch (flags 2-5) or cycle-slip records (flag 6)."""
        kinds = {2: "epoch flag 2 (start moving)", 3: "epoch flag 3 (new site occupation)",
                 4: "epoch flag 4 (header records)", 5: "epoch flag 5 (external event)",
                 6: "epoch flag 6 (cycle-slip records, skipped)"}
        self.note(kinds[flag], i + 1)
        body = self.lines[i + 1:i + 1 + count]
        if len(body) < count:
            raise DataFileError(self.path, f"epoch flag {flag} announces {count} records, the file ends after "
                                f"{len(body)}", i + 1)
        for k, rec in enumerate(body):
            if rec[60:80].strip() in ("SYS / # / OBS TYPES", "# / TYPES OF OBSERV"):
                raise DataFileError(self.path, "observation types redefined inside the data (epoch flag "
                                    f"{flag}): not supported, split the file there", i + 2 + k)
        return i + 1 + count

    def _open_epoch(self, i, t, flag, clock_text) -> int:
        """Record the epoch of line ``i`` (flag 0 or 1) and its receiver clock field; returns its index."""
        if flag == 1:
            self.note("epoch flag 1 (power failure since the previous epoch)", i + 1)
        self.times.append(t)
        self.clocks.append(self._clock(clock_text, i))
        return len(self.times) - 1

    def _epoch3(self, i):
        line = self.lines[i]
        if line[0] != ">":
            raise DataFileError(self.path, "expected an epoch record starting with '>'", i + 1)
        t, flag, count = self._epoch_fields(line, i, True)
        if flag >= 2:
            return self._special(i, flag, count)
        k = self._open_epoch(i, t, flag, line[41:56])
        for j in range(i + 1, i + 1 + count):
            if j >= len(self.lines):
                raise DataFileError(self.path, f"epoch announces {count} satellites, the file ends after "
                                    f"{j - i - 1}", i + 1)
            rec = self.lines[j]
            if not rec.strip():
                raise DataFileError(self.path, f"blank line where a satellite record was expected (the epoch on "
                                    f"line {i + 1} announces {count})", j + 1)
            if rec[0] == ">":
                raise DataFileError(self.path, f"epoch announces {count} satellites but lists {j - i - 1}", i + 1)
            self.records.append((k, _sat_id(rec[:3], self.path, j + 1, self.hdr.file_system), j))
        return i + 1 + count

    def _epoch2(self, i):
        line = self.lines[i]
        t, flag, count = self._epoch_fields(line, i, False)
        if flag >= 2:
            return self._special(i, flag, count)
        k = self._open_epoch(i, t, flag, line[68:80])
        sats, j = [], i
        while len(sats) < count:
            text = self.lines[j][32:68] if j < len(self.lines) else ""
            if j > i and self.lines[j][:32].strip():
                raise DataFileError(self.path, f"epoch announces {count} satellites, its lines list {len(sats)}",
                                    i + 1)
            got = [text[3 * q:3 * q + 3] for q in range(12) if text[3 * q:3 * q + 3].strip()]
            if not got:
                raise DataFileError(self.path, f"epoch announces {count} satellites, its lines list {len(sats)}",
                                    i + 1)
            sats += [_sat_id(s, self.path, j + 1, self.hdr.file_system) for s in got]
            j += 1
        per_sat = -(-len(self.hdr.obs_types[next(iter(self.hdr.obs_types))]) // 5)
        end = j + per_sat * count
        if end > len(self.lines):
            raise DataFileError(self.path, "the file ends inside an epoch's observation records (truncated)", i + 1)
        for q, sat in enumerate(sats):
            self.records.append((k, sat, j + q * per_sat))
        return end


def _field_offsets(n_types: int, v3: bool) -> np.ndarray:
    """Column of the first character of each observation field in a record string (see :func:`_record`)."""
    k = np.arange(n_types)
    return 3 + FIELD * k if v3 else 3 + (k // 5) * 80 + (k % 5) * FIELD


def _convert(chars: np.ndarray, path, where) -> np.ndarray:
    """(R, 14) ASCII bytes of F14.3 fields -> (R,) floats, NaN where blank; a bad field names its line."""
    blank = (chars == 32).all(axis=1)
    work = chars.copy()
    work[blank, :3] = np.frombuffer(b"nan", np.uint8)
    try:
        return work.view("S14").ravel().astype(float)
    except ValueError:
        for r in range(work.shape[0]):
            text = bytes(work[r]).decode("latin-1")
            try:
                float(text)
            except ValueError:
                line, col = where(r)
                raise DataFileError(path, f"expected an observation value (F14.3) in columns {col + 1}-{col + 14}, "
                                    f"found {text.strip()!r}", line) from None
        raise


def _digits(chars: np.ndarray, path, where, what) -> np.ndarray:
    """(R,) ASCII bytes of one-digit flags -> uint8 (blank 0); anything else names its line."""
    ok = (chars == 32) | ((chars >= 48) & (chars <= 57))
    if not ok.all():
        r = int(np.flatnonzero(~ok)[0])
        line, col = where(r)
        raise DataFileError(path, f"expected a digit or blank for the {what} in column {col + 1}, found "
                            f"{chr(chars[r])!r}", line)
    return np.where(chars == 32, 0, chars - 48).astype(np.uint8)


def read(path) -> ObsFile:
    """Parse the RINEX observation file ``path`` (2.10/2.11, 3.0x, 4.00; plain, gzip or Hatanaka)."""
    raw = decompress(path)
    lines = raw.decode("latin-1").splitlines()
    hdr, start = read_header(lines, path)
    walker = _Walker(lines, start, hdr, path)
    walker.walk()
    if not walker.times:
        raise DataFileError(path, "no observation epoch after the header")
    offset = SUPPORTED_TIME_SYSTEMS[hdr.time_system]
    days = np.array([d for d, _ in walker.times], np.int64)
    sod = np.array([s for _, s in walker.times]) + offset
    times = (days - days[0]) * gpstime.SECONDS_PER_DAY + (sod - sod[0])
    if np.any(np.diff(times) <= 0):
        k = int(np.flatnonzero(np.diff(times) <= 0)[0])
        raise DataFileError(path, f"epoch {k + 2} is not later than the epoch before it: epochs must increase")
    week, start_sow = gpstime.normalize(int(days[0]) // 7, (int(days[0]) % 7) * gpstime.SECONDS_PER_DAY + sod[0])
    systems = _systems(walker, hdr, lines, path)
    notes = [f"{kind}: {count} (first at line {walker.first_note[kind]})" for kind, count in walker.notes.items()]
    return ObsFile(str(path), hdr, (int(week), float(start_sow)), times, systems, np.array(walker.clocks), notes)


def _systems(walker: _Walker, hdr: ObsHeader, lines, path) -> dict:
    """The per-system arrays from the satellite records found by the walker."""
    v3 = hdr.version >= 3
    m = len(walker.times)
    by_sys: dict[str, list] = {}
    for k, sat, j in walker.records:
        by_sys.setdefault(sat[0], []).append((k, sat, j))
    out = {}
    for sys, recs in sorted(by_sys.items()):
        if sys not in hdr.obs_types:
            raise DataFileError(path, f"satellite {recs[0][1]}: the header lists no observation types for system "
                                f"{sys!r}", recs[0][2] + 1)
        types = hdr.obs_types[sys]
        n_lines = 1 if v3 else -(-len(types) // 5)
        width = 3 + (FIELD * len(types) if v3 else 80 * n_lines)
        text = []
        for _, _, j in recs:
            if v3:
                text.append(lines[j][:width].ljust(width))
            else:
                text.append("   " + "".join(lines[j + q][:80].ljust(80) for q in range(n_lines)))
        buf = np.frombuffer("".join(text).encode("latin-1"), np.uint8).reshape(len(recs), width)
        sats = sorted({s for _, s, _ in recs})
        col = np.searchsorted(sats, [s for _, s, _ in recs])
        row = np.array([k for k, _, _ in recs])
        dup = np.unique(row * len(sats) + col, return_counts=True)[1] > 1
        if dup.any():
            raise DataFileError(path, f"a satellite of system {sys} appears twice in one epoch")
        values = np.full((m, len(sats), len(types)), np.nan)
        lli = np.zeros((m, len(sats), len(types)), np.uint8)
        ssi = np.zeros((m, len(sats), len(types)), np.uint8)
        first = np.array([j for _, _, j in recs])
        for t_i, off in enumerate(_field_offsets(len(types), v3)):
            def where(r, off=off):
                return int(first[r] + (0 if v3 else (off - 3) // 80)) + 1, int(off if v3 else (off - 3) % 80)
            values[row, col, t_i] = _convert(buf[:, off:off + 14], path, where)
            lli[row, col, t_i] = _digits(buf[:, off + 14], path, lambda r: (where(r)[0], where(r)[1] + 14), "LLI")
            ssi[row, col, t_i] = _digits(buf[:, off + 15], path, lambda r: (where(r)[0], where(r)[1] + 15),
                                         "signal strength")
        out[sys] = SystemObs(sats, list(types), values, lli, ssi)
    return out
