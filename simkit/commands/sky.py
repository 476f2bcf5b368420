"""``simkit sky SOURCE --lat .. --lon .. --start ..``: visible satellites and DOPs over time, and a sky plot."""
from __future__ import annotations

import numpy as np

from ..errors import ScenarioError


def add_parser(sub):
    p = sub.add_parser("sky", help="visible GPS/BDS satellites, DOPs and a sky plot for a place and time span",
                       description="Load a constellation (file, bundled name or nominal:gps / nominal:bds / "
                                   "nominal:bds2 / nominal:bds3 / nominal:gps+bds), evaluate it from one place "
                                   "and print visible counts and DOPs per step; optionally save a sky plot.")
    p.add_argument("source", nargs="?", default=None,
                   help="constellation source (default: the bundled 2026 BRDM broadcast file)")
    p.add_argument("--lat", type=float, required=True, help="latitude, deg")
    p.add_argument("--lon", type=float, required=True, help="longitude, deg")
    p.add_argument("--height", type=float, default=0.0, help="ellipsoidal height, m (default 0)")
    p.add_argument("--start", required=True, help="UTC start, ISO 8601 (e.g. 2026-04-27T06:00:00Z)")
    p.add_argument("--hours", type=float, default=2.0, help="span, h (default 2)")
    p.add_argument("--step", type=float, default=600.0, help="step, s (default 600)")
    p.add_argument("--mask", type=float, default=10.0, help="elevation mask, deg (default 10)")
    p.add_argument("--validity-days", type=float, default=None,
                   help="almanac/TLE sources: days either side of their epoch with valid states (default 7)")
    p.add_argument("--plot", metavar="OUT.png", help="save a sky plot (needs matplotlib)")
    return p


def run(args) -> int:
    from .. import frames, gpstime
    from .. import constellation as sc

    try:
        start = gpstime.parse_utc(args.start)
    except ValueError:
        raise ScenarioError("--start", f"expected an ISO 8601 UTC time, got {args.start!r}") from None
    if args.step <= 0 or args.hours < 0:
        raise ScenarioError("--step", "the step must be > 0 s and the span >= 0 h")
    const = sc.load(args.source or sc.DEFAULT_SKY, validity_days=args.validity_days)
    week, sow0 = gpstime.utc_to_gps(start)
    sow = sow0 + np.arange(0.0, args.hours * 3600.0 + 1e-9, args.step)
    rx = frames.lla_to_ecef(np.radians(args.lat), np.radians(args.lon), args.height)
    geo = sc.receiver_view(const, np.broadcast_to(rx, (sow.size, 3)), week, sow)
    mask = np.radians(args.mask)
    vis = sc.geometry.visible(geo.elevation, mask)
    d = sc.dops(geo.elevation, geo.azimuth, mask, const.system)
    print(f"{const.source}: {len(const)} satellites ({const.kind}); site {args.lat:.4f}, {args.lon:.4f}, "
          f"{args.height:g} m; mask {args.mask:g} deg; one receiver clock per system")
    systems = sorted(set(const.system.tolist()))
    print("UTC                  " + " ".join(f"{s:>3}" for s in systems) + "  all   GDOP   PDOP   HDOP   VDOP")
    for m in range(sow.size):
        utc = gpstime.gps_to_utc(week, sow[m]).strftime("%Y-%m-%d %H:%M:%S")
        counts = " ".join(f"{int(vis[m, const.system == s].sum()):3d}" for s in systems)
        print(f"{utc}  {counts}  {int(vis[m].sum()):3d} " + " ".join(f"{d[k][m]:6.2f}" for k in "GPHV"))
    if args.plot:
        _sky_plot(args.plot, const, geo, vis, f"{const.source} from {args.lat:.2f}, {args.lon:.2f}, {args.start}")
        print(f"sky plot written to {args.plot}")
    return 0


def _sky_plot(path, const, geo, vis, title):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(7, 7))
    ax = fig.add_subplot(projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.set_rlim(90, 0)
    colors = {"G": "tab:blue", "C": "tab:red"}
    for s, sid in enumerate(const.sat_ids):
        ok = vis[:, s]
        if not ok.any():
            continue
        az, el = geo.azimuth[ok, s], np.degrees(geo.elevation[ok, s])
        ax.plot(az, el, ".", ms=3, color=colors.get(sid[0], "k"))
        ax.annotate(f"{sid} {const.orbit_type[s][0]}", (az[-1], el[-1]), fontsize=7)
    ax.set_title(title, fontsize=9)
    fig.savefig(path, dpi=120)
    plt.close(fig)
