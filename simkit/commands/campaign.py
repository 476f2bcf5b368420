"""``simkit campaign SCENARIO --runs N [--grid key=v1,v2 ...] [--workers W | --scheduler ADDRESS] -o DIR``: argument glue around
:func:`simkit.api.campaign`."""
from __future__ import annotations


def add_parser(sub):
    p = sub.add_parser("campaign", help="Monte Carlo runs of a scenario over seeds and parameter grids (Dask)",
                       description="Run SCENARIO N times per grid point (seeds FIRST_SEED, FIRST_SEED+1, ...) on a "
                       "local Dask cluster or an existing one, one HDF5 file per run in DIR/runs, then write "
                       "DIR/summary.json with per-run metrics and campaign statistics. A re-run skips the runs "
                       "already complete (checked by content) and retries the failed ones.")
    p.add_argument("scenario", help="scenario TOML file, or a bundled name such as 'quickstart'")
    p.add_argument("--runs", type=int, required=True, help="runs (seeds) per grid point")
    p.add_argument("--grid", action="append", default=[], metavar="KEY=V1,V2",
                   help="sweep a scenario key over values (TOML literals, the dotted keys of --set; repeatable: "
                   "the cartesian product)")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scenario key in every run (repeatable)")
    p.add_argument("--first-seed", type=int, default=0, help="seed of the first run of each grid point (default 0)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, help="local worker processes (default 2)")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="use a running Dask cluster, e.g. tcp://127.0.0.1:8786 (workers must see DIR)")
    p.add_argument("--metric", dest="metrics", action="append", metavar="NAME",
                   help="per-run metric (repeatable; default: imu_errors, gnss_errors, ambiguity), a registered "
                   "name or package.module:function")
    p.add_argument("--confidence", type=float, default=0.95, help="confidence level of the intervals (default 0.95)")
    p.add_argument("-o", "--out", required=True, metavar="DIR", help="campaign directory")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar or summary line")
    return p


def run(args) -> int:
    from ..api import campaign

    s = campaign(args.scenario, args.out, args.runs, grid=args.grid, overrides=args.overrides,
                 first_seed=args.first_seed, workers=args.workers, scheduler=args.scheduler, metrics=args.metrics,
                 progress=not args.quiet, confidence=args.confidence)
    if not args.quiet:
        c = s["counts"]
        print(f"{c['completed']}/{c['planned']} runs complete ({c['skipped']} already done, {c['failed']} failed) "
              f"in {s['elapsed_s']:.1f} s; summary in {args.out}/summary.json")
        for point in s["points"]:
            for name, r in point["rates"].items():
                if r["rate"] is not None:
                    print(f"  {' '.join(point['overrides']) or 'all runs'}: {name} {r['rate']:.4f} "
                          f"[{r['ci'][0]:.4f}, {r['ci'][1]:.4f}] ({r['successes']}/{r['trials']})")
    return 1 if s["counts"]["failed"] else 0
