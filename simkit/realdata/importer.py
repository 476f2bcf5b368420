"""``simkit import``: a real receiver's RINEX observations (and broadcast navigation) as a simkit file.

The file has the layout of a simulated one (:mod:`simkit.io.schema`) without ``/truth``: ``/gnss/obs/<signal>``
for every signal simkit knows (mapped by :func:`simkit.gnss.rinex_obs.signal_name`), one antenna with a zero lever
arm (the antenna reference point is the file's point), and ``/reference/pos_ecef`` when a reference position is
known. Observation codes and systems simkit does not know are counted in the import report, never dropped
silently.

Satellite positions and clocks are those of the broadcast ephemerides at the emission time found from each
pseudorange, as RTKLIB's ``satposs`` does: t_tx = t_rx - P/c - dT(t_tx), where t_rx is the epoch's time tag
(receiver time) and P the first code of the satellite in the file's signal order, so the receiver clock offset
cancels; in the ECEF frame of emission (the schema's convention). A satellite-epoch without any code gets the
light time from the reference position when there is one, else NaN.

The reference is the header's APPROX POSITION XYZ moved by ANTENNA: DELTA H/E/N (the antenna reference point),
or the position given by the user; the antenna's phase-centre offsets (centimetres) are not applied.
"""
from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import frames, gpstime
from ..constellation.sky import load_sky
from ..constellation.geometry import receiver_view
from ..earth import C_LIGHT
from ..errors import DataFileError, InputError
from ..gnss import signals as sigmod
from ..gnss.rinex_obs import KINDS, ObsFile, read, signal_name
from ..gnss.simulator import _GD_NAMES, _GD_PREFERRED

SYSTEM_ORDER = "GCEJRIS"
OBS_FIELDS = ("code", "carrier", "doppler", "cn0", "lli")


@dataclass(frozen=True)
class Imported:
    """Arrays of an imported file, named as in :mod:`simkit.io.schema` (paths relative to the file root), the
    root attributes, and ``report`` (JSON-ready: counts of what was kept and skipped, notes)."""

    datasets: dict
    attrs: dict
    group_attrs: dict
    report: dict = field(default_factory=dict)


def input_files(obs, navs=(), others=()) -> tuple[Path, list[Path]]:
    """The observation file and the navigation files of ``simkit import`` / ``simkit twin``, checked before any
    work: (obs path, nav paths). A navigation file is a path or, as for ``simkit sky``, the name of a bundled
    data file (:func:`simkit.constellation.sources.resolve`: the documented commands work from any folder).
    ``others`` (a trajectory log, a reference file) must exist as given. DataFileError names the one missing."""
    from ..constellation.sources import bundled_files, resolve

    def existing(path, what):
        p = Path(path)
        if p.is_dir():
            raise DataFileError(path, f"is a directory, expected a {what}")
        if not p.is_file():
            raise DataFileError(path, f"no such {what}")
        return p

    nav_paths = []
    for nav in navs:
        if Path(nav).is_dir():
            raise DataFileError(f"--nav {nav}", "is a directory, expected a RINEX navigation file")
        try:
            nav_paths.append(resolve(nav))
        except DataFileError:
            bundled = [n for n in bundled_files() if re.search(r"\.rnx(\.gz)?$|\.\d\d[nNcCgGlLpP](\.gz)?$", n)]
            raise DataFileError(f"--nav {nav}", "no such file, and not a bundled navigation file (bundled: "
                                f"{', '.join(bundled)})") from None
    for other in others:
        if other is not None:
            existing(other, "file")
    return existing(obs, "RINEX observation file"), nav_paths


def parse_reference(text: str | None, file: str | None):
    """(pos (3,) m ECEF, source) of ``--reference X,Y,Z`` or ``--reference-file F`` (three numbers X Y Z in
    metres, ECEF; lines starting with '#' ignored), or (None, None)."""
    if text is not None and file is not None:
        raise InputError("--reference", "give --reference or --reference-file, not both")
    if text is not None:
        parts = text.replace(" ", "").split(",")
        try:
            pos = np.array([float(p) for p in parts])
        except ValueError:
            pos = np.zeros(0)
        if pos.shape != (3,) or not np.isfinite(pos).all():
            raise InputError("--reference", f"expected X,Y,Z in metres (ECEF), got {text!r}")
        _check_reference(pos, "--reference")
        return pos, "user (--reference)"
    if file is not None:
        try:
            body = Path(file).read_text(encoding="latin-1")
        except OSError as exc:
            raise InputError("--reference-file", f"{file}: cannot read ({exc.strerror or exc})") from None
        words = " ".join(ln.split("#")[0] for ln in body.splitlines()).replace(",", " ").split()
        try:
            pos = np.array([float(w) for w in words])
        except ValueError:
            pos = np.zeros(0)
        if pos.shape != (3,):
            raise DataFileError(file, "expected three numbers X Y Z in metres (ECEF)")
        _check_reference(pos, f"--reference-file {file}")
        return pos, f"user (--reference-file {Path(file).name})"
    return None, None


def _check_reference(pos, what):
    r = np.linalg.norm(pos)
    if not 6.0e6 < r < 4.5e7:
        raise InputError(what, f"|X,Y,Z| = {r:.0f} m is not a position near the Earth (expected metres, ECEF)")


def header_reference(obs: ObsFile):
    """(pos (3,) m, source) of the antenna reference point from the header, or (None, None)."""
    hdr = obs.header
    if hdr.approx_pos_ecef is None:
        return None, None
    h, e, n = hdr.antenna_delta_hen
    lla = frames.ecef_to_lla(hdr.approx_pos_ecef[None])[0]
    delta = frames.enu_to_ecef_vec(np.array([[e, n, h]]), lla[0:1], lla[1:2])[0]
    return hdr.approx_pos_ecef + delta, "RINEX header (APPROX POSITION XYZ + ANTENNA: DELTA H/E/N)"


def _sat_key(sat: str):
    return SYSTEM_ORDER.find(sat[0]) if sat[0] in SYSTEM_ORDER else len(SYSTEM_ORDER), sat


def _columns(obs: ObsFile):
    """Which (system, type index) feeds each (signal, kind), and the counts of what is skipped."""
    version = obs.header.version
    feeds: dict[str, dict[str, list]] = {}
    skipped_codes: dict[str, int] = {}
    skipped_systems: dict[str, dict] = {}
    for sys, so in obs.systems.items():
        known_any = False
        for k, code in enumerate(so.types):
            name = signal_name(sys, code, version) if code[0] in KINDS else None
            count = int(np.isfinite(so.values[..., k]).sum())
            if name is None:
                if count:
                    skipped_codes[f"{sys} {code}"] = count
                continue
            known_any = True
            feeds.setdefault(name, {}).setdefault(KINDS[code[0]], []).append((sys, k))
        if not known_any:
            skipped_systems[sys] = {"satellites": len(so.sats),
                                    "observations": int(np.isfinite(so.values).sum())}
    skipped_codes = {k: v for k, v in skipped_codes.items() if k[0] not in skipped_systems}
    return feeds, skipped_codes, skipped_systems


def build(obs: ObsFile, nav_paths=(), reference=None, reference_source=None) -> Imported:
    """The simkit arrays of the parsed observation file ``obs`` with the broadcast ephemerides of ``nav_paths``
    (a NaN orbit without them) and an optional ``reference`` (3,) m ECEF (default: from the header)."""
    feeds, skipped_codes, skipped_systems = _columns(obs)
    if not feeds:
        known = ", ".join(f"{s.system} {'/'.join(s.rinex_codes())}" for s in sigmod.SIGNALS.values())
        raise DataFileError(obs.path, f"no observation of a signal simkit knows ({known}); the file has "
                            + "; ".join(f"{s}: {' '.join(o.types)}" for s, o in obs.systems.items()))
    signals = [n for n in sigmod.SIGNALS if n in feeds]
    systems = sorted({sigmod.get(n).system for n in signals}, key=SYSTEM_ORDER.find)
    sats = sorted({s for sys in systems for s in obs.systems[sys].sats}, key=_sat_key)
    m = obs.t.size
    ds, first_code = _signal_arrays(obs, feeds, signals, sats)
    if reference is None:
        reference, reference_source = header_reference(obs)
    report = {"epochs": m, "span_s": float(obs.t[-1]), "signals": signals, "satellites": len(sats),
              "observations": {name: {k: int(np.isfinite(ds[f"gnss/obs/{name}/{k}"]).sum())
                                      for k in ("code", "carrier", "doppler", "cn0")} for name in signals},
              "skipped_codes": skipped_codes, "skipped_systems": skipped_systems, "notes": list(obs.notes),
              "reference": reference_source or "none"}
    week, sow0 = obs.start
    sow = sow0 + obs.t
    pos, clk, gd, iono, nav_channels = _satellites(obs, nav_paths, sats, signals, first_code, reference, report)
    ds.update({"gnss/t": obs.t, "gnss/sat_id": np.array(sats), "gnss/signals": np.array(signals),
               "gnss/frequency_hz": np.array([sigmod.get(n).freq_hz for n in signals]),
               "gnss/sat_frequency_hz": _sat_frequencies(sats, signals, obs.header.glonass_channels, nav_channels,
                                                         report),
               "gnss/wavelength_m": np.array([sigmod.get(n).wavelength_m for n in signals]),
               "gnss/group_delay": gd, "gnss/sat_pos_ecef": pos, "gnss/sat_clock": clk,
               "gnss/antennas/lever_arm_b": np.zeros((1, 3)),
               "gnss/antennas/boresight_b": np.array([[0.0, 0.0, 1.0]])})
    if iono:
        ds["gnss/iono_systems"] = np.array(list(iono), dtype="U1")
        ds["gnss/iono_alpha"] = np.array([iono[k][0] for k in iono], dtype=float).reshape(-1, 4)
        ds["gnss/iono_beta"] = np.array([iono[k][1] for k in iono], dtype=float).reshape(-1, 4)
    group_attrs = {}
    if reference is not None:
        ds["reference/pos_ecef"] = np.asarray(reference, float)
        group_attrs["reference"] = {"source": reference_source, "kind": "static"}
    hdr = obs.header
    interval = hdr.interval_s or (float(np.median(np.diff(obs.t))) if m > 1 else 0.0)
    group_attrs["gnss"] = {"rate_hz": 1.0 / interval if interval else 0.0,
                           "receiver": hdr.receiver, "antenna": hdr.antenna, "marker": hdr.marker}
    attrs = {"scenario_toml": "", "scenario_name": f"import of {Path(obs.path).name}",
             "start_gps_week": int(week), "start_gps_sow": float(sow[0]),
             "imported_from": json.dumps({"obs": Path(obs.path).name, "nav": [Path(p).name for p in nav_paths],
                                          "rinex_version": hdr.version}),
             "import_report": json.dumps(report)}
    return Imported(ds, attrs, group_attrs, report)


def _signal_arrays(obs, feeds, signals, sats):
    """{/gnss/obs/<signal>/<kind>: (M, 1, S)} and each satellite-epoch's first code (M, S) m in signal order."""
    col = {s: i for i, s in enumerate(sats)}
    m, n_s = obs.t.size, len(sats)
    ds: dict[str, np.ndarray] = {}
    first_code = np.full((m, n_s), np.nan)
    for name in signals:
        arrays = {k: np.full((m, 1, n_s), np.nan) for k in ("code", "carrier", "doppler", "cn0")}
        lli = np.zeros((m, 1, n_s), np.uint8)
        for kind, sources in feeds[name].items():
            for sys, k in sources:
                so = obs.systems[sys]
                cols = [col[s] for s in so.sats]
                arrays[kind][:, 0, cols] = so.values[..., k]
                if kind == "carrier":
                    lli[:, 0, cols] = so.lli[..., k]
        for kind, a in arrays.items():
            ds[f"gnss/obs/{name}/{kind}"] = a
        ds[f"gnss/obs/{name}/lli"] = lli
        fill = np.isnan(first_code)
        first_code[fill] = arrays["code"][:, 0][fill]
    return ds, first_code


def _satellites(obs, nav_paths, sats, signals, first_code, reference, report):
    """Satellite positions (M, S, 3) m and clocks (M, S) s at emission, group delays (S, G) m, Klobuchar."""
    m, n_s = first_code.shape
    pos, clk = np.full((m, n_s, 3), np.nan), np.full((m, n_s), np.nan)
    gd = np.zeros((n_s, len(signals)))
    if not nav_paths:
        report["navigation"] = "none: satellite orbits and clocks are NaN (give --nav)"
        return pos, clk, gd, {}, {}
    sky = load_sky(nav_paths)
    used_sys = sorted({s[0] for s in sats}, key=SYSTEM_ORDER.find)
    nav_sys = sorted({s[0] for c in sky.constellations for s in c.sat_ids}, key=SYSTEM_ORDER.find)
    missing = [s for s in used_sys if s not in nav_sys]
    if not any(s in nav_sys for s in used_sys):
        raise DataFileError(nav_paths[0], f"no broadcast ephemeris for the observed systems "
                            f"{', '.join(used_sys)} (the navigation data has {', '.join(nav_sys) or 'none'})")
    week, sow0 = obs.start
    rx_sow = sow0 + obs.t
    tau = first_code / C_LIGHT
    if reference is not None:
        nocode = np.isnan(tau)
        if nocode.any():
            view = receiver_view_all(sky, sats, reference, week, rx_sow)
            tau[nocode] = view[nocode]
    have = np.zeros(n_s, bool)
    for const in sky.constellations:
        idx = [i for i, s in enumerate(sats) if s in const.sat_ids and not have[i]]
        if not idx:
            continue
        sel = [const.sat_ids.index(sats[i]) for i in idx]
        t_w, t_s = gpstime.add_seconds(week, rx_sow[:, None], -tau[:, idx])
        t_w = np.broadcast_to(t_w, t_s.shape)
        _, dts = _state_of(const, t_w, t_s, sel)
        t_w2, t_s2 = gpstime.add_seconds(t_w, t_s, -np.nan_to_num(dts))
        p, c = _state_of(const, t_w2, t_s2, sel)
        pos[:, idx], clk[:, idx] = p, c
        have[idx] = True
    if not np.isfinite(pos).any():
        from ..constellation.model import describe_span

        first, last = (gpstime.gps_to_utc(*gpstime.normalize(week, x)) for x in (rx_sow[0], rx_sow[-1]))
        spans = "; ".join(f"{Path(c.source).name}: {describe_span(c.validity_span())}" for c in sky.constellations)
        when = f"{first:%Y-%m-%d %H:%M:%S} to {last:%Y-%m-%d %H:%M:%S} UTC"
        raise DataFileError(nav_paths[0], f"no broadcast record is valid during the observations ({when}); the "
                            f"navigation data covers {spans}")
    gds = _group_delays(sky, sats, signals, week, rx_sow[m // 2])
    gd = gds * C_LIGHT
    orbit_ok = np.isfinite(pos[..., 0]) | np.isnan(first_code)
    report["navigation"] = ", ".join(Path(p).name for p in nav_paths)
    if missing:
        report["notes"].append(f"navigation data without system(s) {', '.join(missing)}: their orbits are NaN")
    no_orbit = [s for i, s in enumerate(sats) if not have[i]]
    if no_orbit:
        report["notes"].append(f"no broadcast record for {len(no_orbit)} satellite(s): {' '.join(no_orbit)}")
    gap = int((~orbit_ok).sum()) - sum(int(np.isfinite(first_code[:, i]).sum()) for i, s in enumerate(sats)
                                       if not have[i])
    if gap > 0:
        report["notes"].append(f"{gap} satellite-epoch(s) with code outside every broadcast record's validity")
    iono = {k: sky.klobuchar(k) for k in used_sys if sky.klobuchar(k) is not None}
    channels = {sid: int(k) for sid, k in zip(sky.sat_ids, sky.channels) if sid[0] == "R"}
    return pos, clk, gd, iono, channels


def _sat_frequencies(sats, signals, header_channels: dict, nav_channels: dict, report) -> np.ndarray:
    """Carrier frequency (S, G) Hz of each satellite and signal: the signal's own, and for an FDMA (GLONASS)
    signal that of the satellite's frequency number, from the header's 'GLONASS SLOT / FRQ #' or else from its
    navigation records (NaN, and a note, where neither gives one)."""
    out = np.empty((len(sats), len(signals)))
    unknown = []
    for j, name in enumerate(signals):
        g = sigmod.get(name)
        for i, sat in enumerate(sats):
            if not g.is_fdma:
                out[i, j] = g.freq_hz
                continue
            if sat[0] != g.system:    # another system's satellite does not transmit the FDMA signal
                out[i, j] = np.nan
                continue
            k = header_channels.get(sat, nav_channels.get(sat))
            out[i, j] = np.nan if k is None else float(g.frequency_for(k))
            if k is None and sat not in unknown:
                unknown.append(sat)
    if unknown:
        report["notes"].append(f"no GLONASS frequency number (header 'GLONASS SLOT / FRQ #' or navigation record) "
                               f"for {' '.join(unknown)}: their FDMA carrier frequencies are NaN")
    return out


def _state_of(const, t_w, t_s, sel):
    """Positions and clocks of constellation ``const``'s satellites ``sel`` at per-cell times (M, len(sel))."""
    n = len(const.sat_ids)
    full_w = np.zeros((t_s.shape[0], n), np.int64)
    full_s = np.zeros((t_s.shape[0], n))
    full_w[:, sel], full_s[:, sel] = t_w, np.nan_to_num(t_s)
    p, c = const.state_each(full_w, full_s)
    p, c = p[:, sel], c[:, sel]
    bad = ~np.isfinite(t_s)
    p[bad], c[bad] = np.nan, np.nan
    return p, c


def receiver_view_all(sky, sats, reference, week, rx_sow):
    """Light time (M, S) s from each satellite to the fixed ``reference`` (3,) m, NaN without an orbit."""
    out = np.full((rx_sow.size, len(sats)), np.nan)
    rx = np.broadcast_to(np.asarray(reference, float), (rx_sow.size, 3))
    for const in sky.constellations:
        idx = [i for i, s in enumerate(sats) if s in const.sat_ids]
        if idx:
            view = receiver_view(const, rx, week, rx_sow)
            take = [const.sat_ids.index(sats[i]) for i in idx]
            fill = np.isnan(out[:, idx])
            out[:, idx] = np.where(fill, view.tau[:, take], out[:, idx])
    return out


def _group_delays(sky, sats, signals, week, sow) -> np.ndarray:
    """Broadcast group delays (S, G) s per satellite and signal, from the records nearest ``(week, sow)``: the
    simulator's rule (:mod:`simkit.gnss.simulator`), 0 where the navigation data has none."""
    gds = sky.group_delays(week, sow)
    index = {s: i for i, s in enumerate(sky.sat_ids)}
    rows = np.array([index.get(s, -1) for s in sats])
    out = np.zeros((len(sats), len(signals)))
    for j, name in enumerate(signals):
        g = sigmod.get(name)
        for key in _GD_PREFERRED.get(name, ()) + _GD_NAMES.get(g.tgd, ()):
            if key not in gds:
                continue
            vals = np.where(rows >= 0, gds[key][np.maximum(rows, 0)], np.nan)
            fill = np.isfinite(vals) & (out[:, j] == 0.0) & (np.array([s[0] for s in sats]) == g.system)
            scale = g.tgd_scale if key in _GD_NAMES.get(g.tgd, ()) else 1.0
            out[fill, j] = vals[fill] * scale
    return out


def import_rinex(obs_path, nav_paths=(), reference=None, reference_source=None) -> Imported:
    """Parse ``obs_path`` and build its simkit arrays (see :func:`build`)."""
    return build(read(obs_path), list(nav_paths), reference, reference_source)


def write(path, imported: Imported) -> Path:
    """Write ``imported`` as a simkit HDF5 file at ``path`` (atomically: a temporary name renamed when
    complete). Time series are chunked and compressed like a simulated file's."""
    from ..io import Writer

    with Writer(path, imported.attrs) as w:
        for group, attrs in imported.group_attrs.items():
            w.group_attrs(group, attrs)
        for name, data in imported.datasets.items():
            if name.startswith("gnss/obs/") or name in ("gnss/t", "gnss/sat_pos_ecef", "gnss/sat_clock"):
                w.append(name, data)
            else:
                w.write(name, data)
    return Path(path)


def describe(imported: Imported, out) -> str:
    """The import report as text lines (what ``simkit import`` prints)."""
    r = imported.report
    lines = [f"{out}: {r['epochs']} epochs over {r['span_s']:.0f} s, {r['satellites']} satellites, signals "
             f"{', '.join(r['signals'])}",
             f"navigation: {r.get('navigation', 'none')}", f"reference: {r['reference']}"]
    for name, counts in r["observations"].items():
        lines.append(f"  {name}: " + ", ".join(f"{k} {v}" for k, v in counts.items()))
    if r["skipped_codes"]:
        lines.append("skipped codes simkit has no signal for (observations): "
                     + ", ".join(f"{k} {v}" for k, v in r["skipped_codes"].items()))
    if r["skipped_systems"]:
        lines.append("skipped systems simkit does not simulate: "
                     + ", ".join(f"{k} ({v['satellites']} satellites, {v['observations']} observations)"
                                 for k, v in r["skipped_systems"].items()))
    lines += [f"note: {n}" for n in r["notes"]]
    return "\n".join(lines) + "\n"
