"""``simkit solve FILE.h5 [--filter NAME ...] [--set estimator.key=value ...]``: estimators into /solutions.

Argument glue around :func:`simkit.api.solve` (filter names from :func:`simkit.api.registry`: spp, kf15, kf15_dd,
kf21, hinf and the attitude solvers). Each writes ``/solutions/<name>`` (replacing only that group, atomically). Every
argument is checked (file, filter names, keys, every filter's values against :mod:`simkit.params` and the file)
before any filter runs: bad input is one line, exit 2, and the file is left as it was. A filter that then fails on
the file's data is reported in one line naming it and writes nothing; the other filters still run, and the exit
code is 1.
"""
from __future__ import annotations

import sys

from ..errors import ScenarioError
from ..params import parse_set


def add_parser(sub):
    p = sub.add_parser("solve", help="run estimators on a simkit file and store their solutions",
                       description="Run one or more estimators (single-point positioning, Kalman and H-infinity "
                                   "INS/GNSS filters, attitude solvers when installed) on a simkit HDF5 file and "
                                   "write each to /solutions/<name>.")
    p.add_argument("file", help="simkit HDF5 file (written by simkit run), updated in place")
    p.add_argument("--filter", action="append", dest="filters", metavar="NAME",
                   help="estimator to run (repeatable; default: spp and kf15); see docs/estimators.md")
    p.add_argument("--set", action="append", dest="overrides", default=[], metavar="estimator.KEY=VALUE",
                   help="override an estimator parameter (a TOML literal), e.g. --set estimator.gnss=truth")
    p.add_argument("--name", help="solution group name (default: the filter name; only with one --filter)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar or summary")
    return p


def _check_name(name, filters) -> None:
    """``--name``: only with one filter, and a valid /solutions group name."""
    from ..io.solutions import _NAME

    if len(filters) != 1:
        raise ScenarioError("--name", "only valid with exactly one --filter")
    if not _NAME.match(name) or name.startswith("."):
        raise ScenarioError("--name", f"expected letters, digits, '_', '-' or '.' (not first), got {name!r}")


def run(args) -> int:
    from tqdm import tqdm

    from .. import api
    from ..io import write_solution

    filters = api.check_filters(args.filters)
    if args.name is not None:
        _check_name(args.name, filters)
    params = parse_set(args.overrides)
    failed = []

    def done(name, sol, why):
        """Write each solution as soon as its filter ends; a failure is one line."""
        if sol is None:
            failed.append(name)
            tqdm.write(f"simkit solve: {name}: failed: {why}", file=sys.stderr)
            return
        write_solution(args.file, args.name or name, sol)
        if not args.quiet:
            tqdm.write(f"/solutions/{args.name or name}: {sol.t.size} epochs", file=sys.stderr)

    api.solve(args.file, filters, params, progress=not args.quiet, on_each=done)
    return 1 if failed else 0
