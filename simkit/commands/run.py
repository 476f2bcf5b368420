"""``simkit run SCENARIO [-o OUT.h5] [--seed N] [--set key=value ...]``."""
from __future__ import annotations

import time


def add_parser(sub):
    p = sub.add_parser("run", help="simulate a scenario into an HDF5 file",
                       description="Simulate SCENARIO (a TOML file or a bundled scenario name) into one HDF5 file.")
    p.add_argument("scenario", help="scenario TOML file, or a bundled name such as 'quickstart'")
    p.add_argument("-o", "--out", help="output file (default: <scenario name>.h5 in the current folder)")
    p.add_argument("--seed", type=int, help="override scenario.seed")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override any scenario key, e.g. --set scenario.duration_s=60 (repeatable)")
    p.add_argument("--force", action="store_true",
                   help="run even when the estimated output exceeds the free disk space or the size limit, or when -o "
                        "names a file that is not a simkit file without /solutions (it is then replaced)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar or summary")
    return p


def run(args) -> int:
    from ..pipeline import run as simulate

    t0 = time.perf_counter()
    out = simulate(args.scenario, out=args.out, seed=args.seed, overrides=args.overrides, progress=not args.quiet,
                   force=args.force)
    if not args.quiet:
        print(f"wrote {out} in {time.perf_counter() - t0:.1f} s")
    return 0
