"""``simkit export FILE.h5 --format rosbag2|csv|kml -o OUT``: the file in the formats other tools read."""
from __future__ import annotations


def add_parser(sub):
    from ..export import BODY_FRAMES, FORMATS, STAMPS

    p = sub.add_parser("export", help="export a simkit file as a ROS 2 bag, CSV files or KML tracks",
                       description="Write the truth, IMU, antenna and solution streams of FILE.h5 as a ROS 2 bag "
                                   "(REP-103/105 frames, needs the 'export' extra), one CSV per stream in a "
                                   "declared convention, or KML tracks for a map (docs/logs_and_export.md).")
    p.add_argument("file", help="simkit HDF5 file (with /truth)")
    p.add_argument("--format", required=True, choices=FORMATS, help="output format")
    p.add_argument("-o", "--out", required=True, help="output: a folder for rosbag2 and csv, a .kml file for kml")
    p.add_argument("--frame", default="ned-frd", choices=BODY_FRAMES,
                   help="CSV convention: navigation and body axes (default ned-frd)")
    p.add_argument("--stamp", default="unix", choices=STAMPS,
                   help="bag stamps: unix (UTC, as ROS time), gps (since 1980-01-06) or start (since the "
                        "scenario start); default unix")
    p.add_argument("--fix-sigma-m", type=float, default=0.0,
                   help="white noise (m, per ENU axis) added to the bag's NavSatFix positions (default 0)")
    p.add_argument("--seed", type=int, default=0, help="seed of that noise (default 0)")
    p.add_argument("--kml-rate-hz", type=float, default=1.0, help="KML points per second (default 1)")
    return p


def run(args) -> int:
    from ..api import export
    from ..io.output import check_output

    folder = args.format != "kml"
    check_output(args.out, [args.file], option="-o", folder=folder)
    for path in export(args.file, args.format, args.out, frame=args.frame, stamp=args.stamp,
                       fix_sigma_m=args.fix_sigma_m, seed=args.seed, rate_hz=args.kml_rate_hz):
        print(path)
    return 0
