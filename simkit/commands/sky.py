"""``simkit sky SOURCE --lat .. --lon .. --start ..``: visible satellites and DOPs over time, and a sky plot.

Bad input ends in one line on stderr and exit code 2, checked before any computing: ranges of every number, the
plot's folder and matplotlib, the working memory the span needs (``--force`` to go beyond
:data:`MEMORY_LIMIT_BYTES`), and a sky with no satellite (times the source does not cover, or a mask nothing
clears). Output into a closed pipe (``| head``) ends quietly.
"""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..errors import ScenarioError
from . import silence_stdout

MEMORY_LIMIT_BYTES = 2 * 1024**3
# working memory of the geometry and DOPs per satellite-epoch: the measured peak rounded up (docs/benchmarks.md);
# the per-epoch part covers the time arrays
BYTES_PER_SAT_EPOCH = 256
BYTES_PER_EPOCH = 64
HEIGHT_RANGE_M = (-11000.0, 20.0e6)  # deepest ocean floor .. below the GNSS orbits


def add_parser(sub):
    p = sub.add_parser("sky", help="visible satellites per system, DOPs and a sky plot for a place and time span",
                       description="Load a constellation (file, bundled name or nominal:gps / nominal:bds / "
                                   "nominal:bds2 / nominal:bds3 / nominal:gps+bds / nominal:gal / nominal:glo / "
                                   "nominal:gps+bds+gal+glo), evaluate it from one place "
                                   "and print visible counts and DOPs per step; optionally save a sky plot.")
    p.add_argument("source", nargs="?", default=None,
                   help="constellation source (default: the bundled 2026 BRDM broadcast file)")
    p.add_argument("--lat", type=float, required=True, help="geodetic latitude, deg (-90..90)")
    p.add_argument("--lon", type=float, required=True, help="longitude, deg (-180..360)")
    p.add_argument("--height", type=float, default=0.0,
                   help="ellipsoidal height, m (default 0; -11000 m to 20,000 km)")
    p.add_argument("--start", required=True, help="UTC start, ISO 8601 (e.g. 2026-04-27T06:00:00Z)")
    p.add_argument("--hours", type=float, default=2.0, help="span, h (>= 0, default 2)")
    p.add_argument("--step", type=float, default=600.0, help="step, s (> 0, default 600)")
    p.add_argument("--mask", type=float, default=10.0, help="elevation mask, deg (-90..90, default 10)")
    p.add_argument("--validity-days", type=float, default=None,
                   help="almanac/TLE sources: days either side of their epoch with valid states (default 7)")
    p.add_argument("--systems", default=None, metavar="LETTERS",
                   help="RINEX navigation sources: the systems to use, e.g. GC (GPS+BDS) or GCEJR (default: every "
                        "GPS, BDS, Galileo, QZSS and GLONASS record of the file)")
    p.add_argument("--plot", metavar="OUT.png", help="save a sky plot (needs matplotlib: the 'plot' extra)")
    p.add_argument("--environment", metavar="FILE.toml",
                   help="a TOML file with an [environment] table (a scenario, or a bundled scenario's name such as "
                        "urban_canyon): the site sees its buildings and "
                        "canyons, placed around the file's trajectory.origin (else around the site); the table "
                        "gains counts of direct, direct+reflected, NLOS and blocked satellites, DOPs use the "
                        "received ones and the plot marks each state")
    p.add_argument("--force", action="store_true",
                   help=f"compute even when the span needs more than {MEMORY_LIMIT_BYTES / 1024**3:g} GiB")
    return p


def run(args) -> int:
    from .. import gpstime
    from .. import constellation as sc

    _check_numbers(args)
    plot_format = _check_plot(args.plot) if args.plot else None
    from ..io.output import check_outputs  # an output never replaces an input

    check_outputs([("--plot", args.plot, False)], [args.source])
    start = _start(args.start)
    const = sc.load(args.source or sc.DEFAULT_SKY, validity_days=args.validity_days, systems=args.systems)
    week, sow0 = gpstime.utc_to_gps(start)
    sow = sow0 + np.arange(_step_count(args, len(const))) * args.step
    const.require_states(week, sow)  # NoStateError: names the source and the span it covers
    env = _environment(args) if args.environment else None
    geo, vis, d = _compute(const, args, week, sow)
    states = None
    if env is not None:
        states = _states(env, args, geo, vis)
        vis = vis & (states <= 2)
        d = sc.dops(np.where(vis, geo.elevation, np.nan), geo.azimuth, np.radians(args.mask), const.system)
    out = _Output()
    _print_table(out, const, args, week, sow, vis, d, states)
    if args.plot:
        from ..plots import sky_figure

        sky_figure(args.plot, plot_format, const, geo, vis if states is None else np.isfinite(geo.elevation) & (
            geo.elevation >= np.radians(args.mask)), f"{const.source} from {args.lat:.2f}, {args.lon:.2f}, "
            f"{args.start}", states)
        out.line(f"sky plot written to {args.plot}")
    return 0


def _check_numbers(args):
    """Each numeric option finite and in range, else one ScenarioError naming the option."""
    limits = {"--lat": (args.lat, -90.0, 90.0, "deg"), "--lon": (args.lon, -180.0, 360.0, "deg"),
              "--height": (args.height, *HEIGHT_RANGE_M, "m"), "--mask": (args.mask, -90.0, 90.0, "deg")}
    for name, (value, lo, hi, unit) in limits.items():
        if not (math.isfinite(value) and lo <= value <= hi):
            raise ScenarioError(name, f"found {value:g}; expected {lo:g} to {hi:g} {unit}")
    if not (math.isfinite(args.hours) and args.hours >= 0):
        raise ScenarioError("--hours", f"found {args.hours:g}; expected a span >= 0 h")
    if not (math.isfinite(args.step) and args.step > 0):
        raise ScenarioError("--step", f"found {args.step:g}; expected a step > 0 s")
    if args.systems is not None and (not args.systems or set(args.systems) - set("GCEJR")):
        raise ScenarioError("--systems", f"found {args.systems!r}; expected letters among G, C, E, J, R")
    days = args.validity_days
    if days is not None and not (math.isfinite(days) and days > 0):
        raise ScenarioError("--validity-days", f"found {days:g}; expected a number of days > 0")


def _check_plot(path_text: str) -> str:
    """Before any computing: the plot's folder exists and is writable, matplotlib imports and knows the file
    type. Returns the file type (the extension)."""
    path = Path(path_text)
    folder = path.parent
    if not folder.is_dir():
        raise ScenarioError("--plot", f"folder {str(folder)!r} does not exist (create it first)")
    if not os.access(folder, os.W_OK):
        raise ScenarioError("--plot", f"folder {str(folder)!r} is not writable")
    from ..plots import image_format

    return image_format(path_text)


def _start(text: str):
    from .. import gpstime

    try:
        start = gpstime.parse_utc(text)
    except ValueError:
        raise ScenarioError("--start", f"expected an ISO 8601 UTC time, got {text!r}") from None
    if start < gpstime.GPS_EPOCH:
        raise ScenarioError("--start", f"{text!r} is before the GPS epoch {gpstime.GPS_EPOCH:%Y-%m-%d}")
    return start


def _step_count(args, n_sats: int) -> int:
    """Number of epochs in the span; ScenarioError when they would need more than MEMORY_LIMIT_BYTES (unless
    --force)."""
    steps = math.floor(args.hours * 3600.0 / args.step + 1e-9) + 1
    need = steps * (n_sats * BYTES_PER_SAT_EPOCH + BYTES_PER_EPOCH)
    if need > MEMORY_LIMIT_BYTES and not args.force:
        raise ScenarioError("--hours", f"{args.hours:g} h at --step {args.step:g} s is {steps:,} epochs x "
                            f"{n_sats} satellites, about {_size(need)} of working memory (limit "
                            f"{_size(MEMORY_LIMIT_BYTES)}): shorten --hours, lengthen --step, or pass --force")
    return steps


def _size(n_bytes: float) -> str:
    for unit, scale in (("TiB", 1024**4), ("GiB", 1024**3), ("MiB", 1024**2)):
        if n_bytes >= scale:
            return f"{n_bytes / scale:.3g} {unit}"
    return f"{n_bytes / 1024:.3g} KiB"


def _compute(const, args, week, sow):
    """Geometry, visibility (M, S) and DOPs; ScenarioError when no satellite clears the mask at any step."""
    from .. import frames
    from .. import constellation as sc
    from ..constellation.model import describe_span

    rx = frames.lla_to_ecef(np.radians(args.lat), np.radians(args.lon), args.height)
    geo = sc.receiver_view(const, np.broadcast_to(rx, (sow.size, 3)), week, sow)
    mask = np.radians(args.mask)
    vis = sc.geometry.visible(geo.elevation, mask)
    if not vis.any():
        first, last = (const.validity_span(week, s) for s in (sow[0], sow[-1]))
        raise ScenarioError("--mask", f"no satellite of {const.source} is at or above {args.mask:g} deg at any "
                            f"step from {_utc(week, sow[0])} to {_utc(week, sow[-1])} (the source covers "
                            f"{describe_span(first)})")
    return geo, vis, sc.dops(geo.elevation, geo.azimuth, mask, const.system)


def _environment(args):
    """The :class:`simkit.environment.Environment` of the ``--environment`` file, around its trajectory origin
    (else the site)."""
    import tomllib

    from ..environment import Environment, parse_config
    from ..section import Section

    from ..scenario.loader import resolve

    try:
        path = resolve(args.environment)  # a file, or a bundled scenario's name, as for `simkit run`
    except ScenarioError as exc:
        raise ScenarioError("--environment", f"{args.environment}: {exc.message}") from None
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ScenarioError("--environment", f"{path}: cannot read: {exc.strerror or exc}") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ScenarioError("--environment", f"{path}: not valid TOML: {exc}") from None
    if not isinstance(data.get("environment"), dict):
        raise ScenarioError("--environment", f"{path}: no [environment] table")
    origin = data.get("trajectory", {}).get("origin") if isinstance(data.get("trajectory"), dict) else None
    try:
        if isinstance(origin, dict):
            o = Section(origin, "trajectory.origin")
            lla = (np.radians(o.get("lat_deg", float)), np.radians(o.get("lon_deg", float)), o.get("height_m", float))
        else:
            lla = (np.radians(args.lat), np.radians(args.lon), args.height)
        return Environment(parse_config(Section(data["environment"], "environment"), lla, path.parent), lla,
                           np.zeros((1, 3)))
    except ScenarioError as exc:
        raise exc.with_source(str(path)) from None


def _states(env, args, geo, vis):
    """Line-of-sight states (T, S) of the site's satellites above the mask (255 for the others)."""
    from .. import frames

    rx = frames.lla_to_ecef(np.radians(args.lat), np.radians(args.lon), args.height)
    el = np.where(np.isfinite(geo.elevation), geo.elevation, -1.0)
    st = env.static(rx, np.nan_to_num(geo.azimuth), el).state[:, 0]
    return np.where(vis, st, 255).astype(np.uint8)


def _utc(week, sow) -> str:
    from .. import gpstime

    return gpstime.gps_to_utc(week, sow).strftime("%Y-%m-%d %H:%M:%S UTC")


def _print_table(out, const, args, week, sow, vis, d, states=None):
    out.line(f"{const.source}: {len(const)} satellites ({const.kind}); site {args.lat:.4f}, {args.lon:.4f}, "
             f"{args.height:g} m; mask {args.mask:g} deg; one receiver clock per system")
    if states is not None:
        out.line(f"environment {args.environment}: counts above the mask are received ones (direct, direct+"
                 "reflected, NLOS); dir d+r nlos blk split them by line-of-sight state")
    systems = sorted(set(const.system.tolist()))
    out.line("UTC                  " + " ".join(f"{s:>3}" for s in systems) + "  all   GDOP   PDOP   HDOP   VDOP"
             + ("  dir d+r nlos blk" if states is not None else ""))
    above = None if states is None else states != 255
    for m in range(sow.size):
        if out.closed:
            return
        counts = " ".join(f"{int(vis[m, const.system == s].sum()):3d}" for s in systems)
        extra = ""
        if states is not None:
            extra = "  " + " ".join(f"{int(((states[m] == k) & above[m]).sum()):3d}" for k in range(3)) + \
                f" {int(((states[m] == 3) & above[m]).sum()):3d}"
        out.line(f"{_utc(week, sow[m])[:19]}  {counts}  {int(vis[m].sum()):3d} "
                 + " ".join(f"{d[k][m]:6.2f}" for k in "GPHV") + extra)


class _Output:
    """Lines to stdout; when the reader goes away (``| head``) the rest is dropped quietly
    (:func:`simkit.commands.silence_stdout`) and the command carries on to its plot."""

    def __init__(self):
        self.closed = False

    def line(self, text: str):
        if self.closed:
            return
        try:
            print(text, flush=True)
        except BrokenPipeError:
            self.closed = True
            silence_stdout()
