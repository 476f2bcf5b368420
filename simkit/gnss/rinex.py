"""RINEX 3.04 observation files (one per antenna) and the navigation data used, for RTKLIB and other tools.

Epoch time tags are receiver time, as a receiver writes them: the true GPS time of the epoch plus that
antenna's receiver clock bias (RINEX 3.04 sec. 5.1), written to 0.1 us. Code (m), phase (cycles), Doppler (Hz)
and signal strength (dB-Hz) use the RINEX 3.04 observation codes of :mod:`simkit.gnss.signals`; the loss-of-lock
indicator carries the /gnss/obs LLI bits, the signal-strength indicator is min(max(floor(C/N0 / 6), 1), 9).
"""
from __future__ import annotations

import shutil
from datetime import datetime, timedelta, timezone
from pathlib import Path

import numpy as np

from .. import frames, gpstime
from ..atomic import atomic_open
from ..earth import C_LIGHT
from ..version import __version__
from . import signals as sigmod

_GPS_EPOCH = gpstime.GPS_EPOCH.replace(tzinfo=None)


def _hdr(text: str, label: str) -> str:
    return f"{text:<60.60}{label:<20}\n"


def _calendar(week: int, sow: float) -> tuple[datetime, float]:
    """GPS (week, sow) -> (calendar time in GPS time, whole seconds; fractional second)."""
    sow = round(float(sow), 7)  # the 0.1 us resolution of the epoch line, rounded once so 60.0000000 never appears
    whole = np.floor(sow)
    return _GPS_EPOCH + timedelta(weeks=int(week), seconds=int(whole)), float(sow - whole)


def _obs_types(sig_names, systems):
    """RINEX obs types per system letter present, in signal order: {"G": ["C1C", "L1C", ...]}."""
    out: dict[str, list[str]] = {}
    for name in sig_names:
        s = sigmod.get(name)
        if s.system in systems:
            out.setdefault(s.system, []).extend(s.rinex_codes())
    return out


def _sys_obs_lines(sys: str, types: list[str]) -> str:
    lines = ""
    for i in range(0, len(types), 13):
        chunk = "".join(f" {t}" for t in types[i:i + 13])
        head = f"{sys}  {len(types):3d}" if i == 0 else " " * 6
        lines += _hdr(head + chunk, "SYS / # / OBS TYPES")
    return lines


def _field(value: float, lli: int = 0, ssi: int = 0) -> str:
    if not np.isfinite(value):
        return " " * 16
    li = str(lli) if lli else " "
    si = str(ssi) if ssi else " "
    return f"{value:14.3f}{li}{si}"


def marker_type(antenna_pos_ecef) -> str:
    """RINEX 3.04 MARKER TYPE of a track (M, 3) m ECEF: GEODETIC when it does not move (< 1 mm), AIRBORNE when
    its height changes by more than 30 m, else GROUND_CRAFT."""
    pos = np.asarray(antenna_pos_ecef, dtype=float)
    pos = pos[np.isfinite(pos).all(axis=1)]
    if pos.shape[0] < 2 or np.ptp(pos, axis=0).max() < 1e-3:
        return "GEODETIC"
    h = frames.ecef_to_lla(pos)[:, 2]
    return "AIRBORNE" if np.ptp(h) > 30.0 else "GROUND_CRAFT"


def glonass_slot_lines(channels: dict) -> str:
    """RINEX 3.04 'GLONASS SLOT / FRQ #' header lines for {"R01": k, ...} (8 satellites a line)."""
    items = sorted(channels.items())
    out = ""
    for i in range(0, len(items), 8):
        head = f"{len(items):3d} " if i == 0 else " " * 4
        out += _hdr(head + "".join(f"{sat} {k:2d} " for sat, k in items[i:i + 8]), "GLONASS SLOT / FRQ #")
    return out


def channels_from_frequencies(sat_ids, signal_names, sat_frequency_hz) -> dict:
    """{GLONASS sat id: FDMA channel k} from /gnss/sat_frequency_hz (S, G) and the signal names (G,)."""
    out = {}
    for j, name in enumerate(signal_names):
        g = sigmod.get(name)
        if g.is_fdma:
            for s, sat in enumerate(sat_ids):
                if sat[0] == g.system:
                    out[sat] = int(round((float(sat_frequency_hz[s, j]) - g.freq_hz) / g.fdma_step_hz))
    return out


def _header(systems, types, first, first_frac, approx_pos_ecef, marker, interval_s, kind, channels=None) -> str:
    """The RINEX 3.04 observation header."""
    mixed = "M" if len(types) > 1 else next(iter(types), "G")
    now = datetime.now(timezone.utc).strftime("%Y%m%d %H%M%S UTC")
    head = _hdr(f"{'3.04':>9}{'':11}{'OBSERVATION DATA':<20}{mixed:<20}", "RINEX VERSION / TYPE")
    head += _hdr(f"{'simkit ' + __version__:<20}{'simkit':<20}{now:<20}", "PGM / RUN BY / DATE")
    head += _hdr("simkit: time tags = true GPS time + receiver clock bias", "COMMENT")
    head += _hdr(marker, "MARKER NAME")
    head += _hdr(kind, "MARKER TYPE")
    head += _hdr(f"{'simkit':<20}{'simkit':<40}", "OBSERVER / AGENCY")
    head += _hdr(f"{'0':<20}{'SIMKIT':<20}{__version__:<20}", "REC # / TYPE / VERS")
    head += _hdr(f"{'0':<20}{'SIMKIT NONE':<20}", "ANT # / TYPE")
    x, y, z = np.asarray(approx_pos_ecef, dtype=float)
    head += _hdr(f"{x:14.4f}{y:14.4f}{z:14.4f}", "APPROX POSITION XYZ")
    head += _hdr(f"{0.0:14.4f}{0.0:14.4f}{0.0:14.4f}", "ANTENNA: DELTA H/E/N")
    for sys in systems:
        if sys in types:
            head += _sys_obs_lines(sys, types[sys])
    if interval_s:
        head += _hdr(f"{interval_s:10.3f}", "INTERVAL")
    head += _hdr(f"{first.year:6d}{first.month:6d}{first.day:6d}{first.hour:6d}{first.minute:6d}"
                 f"{first.second + first_frac:13.7f}{'GPS':>8}", "TIME OF FIRST OBS")
    for sys in systems:
        for code in types.get(sys, []):
            if code[0] == "L":
                head += _hdr(f"{sys} {code} {0.0:8.5f}", "SYS / PHASE SHIFT")
    if "R" in types:
        head += glonass_slot_lines(channels or {})
        # simulated receivers have no GLONASS code-phase bias (RINEX 3.04 sec. 5.12: required with GLONASS)
        head += _hdr(" C1C    0.000 C1P    0.000 C2C    0.000 C2P    0.000", "GLONASS COD/PHS/BIS")
    head += _hdr("", "END OF HEADER")
    return head


def write_obs(path, start_week: int, start_sow: float, t, sat_ids, obs: dict, approx_pos_ecef,
              clock_bias_s=None, marker: str = "SIMKIT", interval_s: float | None = None,
              kind: str = "GEODETIC", glonass_channels: dict | None = None) -> Path:
    """Write one antenna's observations as a RINEX 3.04 observation file.

    ``t`` (M,) s since (start_week, start_sow); ``obs``: signal name -> dict with "code", "carrier", "doppler",
    "cn0" (M, S) float and "lli" (M, S) uint8 for this antenna; ``clock_bias_s`` (M,) receiver clock bias added
    to the time tags (None: true GPS time); ``kind`` the MARKER TYPE; ``glonass_channels`` {"R01": k} for the
    'GLONASS SLOT / FRQ #' header. Written under a temporary name and renamed when complete. Returns the path.
    """
    path = Path(path)
    t = np.asarray(t, dtype=float)
    sat_ids = [str(s) for s in sat_ids]
    systems = sorted({s[0] for s in sat_ids}, key="GCERJI".find)
    types = _obs_types(obs.keys(), systems)
    tag = t if clock_bias_s is None else t + np.asarray(clock_bias_s, dtype=float)
    first, first_frac = _calendar(*gpstime.add_seconds(start_week, start_sow, float(tag[0])))
    head = _header(systems, types, first, first_frac, approx_pos_ecef, marker, interval_s, kind, glonass_channels)

    # per system: which (signal, field) feeds each obs-type column
    columns = {}
    for sys in systems:
        cols = []
        for name, o in obs.items():
            if sigmod.get(name).system == sys:
                ssi = np.clip(np.floor(np.nan_to_num(o["cn0"]) / 6.0), 1, 9).astype(int)
                lli = np.asarray(o["lli"]).astype(int)
                cols += [(o["code"], None, ssi), (o["carrier"], lli, ssi), (o["doppler"], None, None),
                         (o["cn0"], None, None)]
        columns[sys] = cols
    with atomic_open(path, "w") as f:
        _write_epochs(f, head, start_week, start_sow, t, tag, sat_ids, columns)
    return path


def _write_epochs(f, head, start_week, start_sow, t, tag, sat_ids, columns) -> None:
    sys_of = [s[0] for s in sat_ids]
    f.write(head)
    for k in range(t.size):
        cal, frac = _calendar(*gpstime.add_seconds(start_week, start_sow, float(tag[k])))
        lines = []
        for j, sat in enumerate(sat_ids):
            cols = columns.get(sys_of[j])
            if not cols or not any(np.isfinite(c[0][k, j]) for c in cols):
                continue
            fields = [_field(v[k, j], 0 if li is None else li[k, j], 0 if si is None else si[k, j])
                      for v, li, si in cols]
            lines.append(sat + "".join(fields).rstrip())
        f.write(f"> {cal.year:4d} {cal.month:02d} {cal.day:02d} {cal.hour:02d} {cal.minute:02d}"
                f"{cal.second + frac:11.7f}  0{len(lines):3d}\n")
        if lines:
            f.write("\n".join(lines) + "\n")


def copy_nav(sources, out_dir) -> list[Path]:
    """Copy the RINEX navigation files among ``sources`` (paths) into ``out_dir``; returns the new paths.

    Gzipped files are decompressed so that every reader (RTKLIB's included) can open them directly.
    """
    import gzip

    out_dir = Path(out_dir)
    out = []
    for src in sources:
        src = Path(src)
        if src.suffix == ".gz":
            dst = out_dir / src.with_suffix("").name
            with gzip.open(src, "rb") as fi, open(dst, "wb") as fo:
                shutil.copyfileobj(fi, fo)
        else:
            dst = out_dir / src.name
            shutil.copyfile(src, dst)
        out.append(dst)
    return out


def export(gnss, start_week: int, start_sow: float, out_dir, nav_sources=(), name: str = "simkit") -> list[Path]:
    """Write one RINEX 3.04 observation file per antenna, plus copies of the RINEX navigation sources.

    ``gnss`` maps paths relative to /gnss to arrays (numpy or lazy :class:`simkit.io.Array`): needs ``t``, ``sat_id``, ``obs/<signal>/...``,
    ``truth/receiver_clock`` (m, for the time tags) and ``truth/antenna_pos_ecef`` (approximate position).
    ``nav_sources``: constellation sources; those that are files are copied (``nominal:`` ones have no file).
    Returns the written paths (observation files first).
    """
    from ..constellation.sources import resolve

    out_dir = Path(out_dir)
    t = np.asarray(gnss["t"][...], dtype=float)
    sat_ids = [s.decode() if isinstance(s, bytes) else str(s) for s in np.asarray(gnss["sat_id"][...])]
    sig_names = [n for n in sigmod.SIGNALS if f"obs/{n}/code" in gnss]
    clock = np.asarray(gnss["truth/receiver_clock"][...], dtype=float) / C_LIGHT
    track = np.asarray(gnss["truth/antenna_pos_ecef"][...], dtype=float)
    ant_pos = track[0]
    interval = float(np.median(np.diff(t))) if t.size > 1 else None
    channels = {}
    if "sat_frequency_hz" in gnss and "signals" in gnss:
        names = [s.decode() if isinstance(s, bytes) else str(s) for s in np.asarray(gnss["signals"][...])]
        channels = channels_from_frequencies(sat_ids, names, np.asarray(gnss["sat_frequency_hz"][...]))
    paths = []
    for a in range(ant_pos.shape[0]):
        obs = {n: {f: np.asarray(gnss[f"obs/{n}/{f}"][:, a, :]) for f in ("code", "carrier", "doppler", "cn0", "lli")}
               for n in sig_names}
        paths.append(write_obs(out_dir / f"{name}_ant{a}.rnx", start_week, start_sow, t, sat_ids, obs,
                               ant_pos[a], clock[:, a], marker=f"{name.upper()}_ANT{a}", interval_s=interval,
                               kind=marker_type(track[:, a]), glonass_channels=channels))
    files = [resolve(s) for s in nav_sources if not str(s).startswith("nominal:")]
    return paths + copy_nav(files, out_dir)
