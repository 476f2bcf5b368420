"""``simkit solve FILE.h5 [--filter NAME ...] [--set estimator.key=value ...]``: estimators into /solutions.

Filter names come from ``simkit.estimators.SOLVERS`` (spp, kf15, kf15_dd, kf21, hinf) and, when that package exists, from
``simkit.attitude.SOLVERS``. Each writes ``/solutions/<name>`` (replacing only that group, atomically). Every
argument is checked (file, filter names, keys, values) before any filter runs.
"""
from __future__ import annotations

import importlib
import importlib.util
import sys

from ..errors import ScenarioError


def registry() -> dict:
    """Every known filter name -> solver callable ``(ds, params, progress) -> Solution``."""
    from ..estimators import SOLVERS

    out = dict(SOLVERS)
    if importlib.util.find_spec("simkit.attitude") is not None:
        out.update(getattr(importlib.import_module("simkit.attitude"), "SOLVERS", {}))
    return out


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


def parse_overrides(items: list[str]) -> dict:
    """``estimator.key=value`` items -> {key: value} (values parsed as TOML literals)."""
    from ..scenario.loader import parse_value

    params = {}
    for item in items:
        if "=" not in item:
            raise ScenarioError("--set", f"expected estimator.key=value, got {item!r}")
        key, text = item.split("=", 1)
        key = key.strip()
        if not key.startswith("estimator.") or len(key) <= len("estimator."):
            raise ScenarioError("--set", f"{key!r}: expected a key of the form estimator.<name>")
        params[key[len("estimator."):]] = parse_value(text.strip())
    return params


def _check(args, known):
    filters = args.filters or ["spp", "kf15"]
    for name in filters:
        if name not in known:
            raise ScenarioError("--filter", f"unknown filter {name!r} (known: {', '.join(sorted(known))})")
    if args.name is not None and len(filters) != 1:
        raise ScenarioError("--name", "only valid with exactly one --filter")
    return filters


def split_params(filters: list[str], params: dict) -> dict:
    """Each filter's share of the ``--set`` keys: simkit.estimators filters take the keys they know; any other
    filter (simkit.attitude) takes the keys none of those knows and checks them itself. A key no requested
    filter can take is an error naming it."""
    from ..estimators.registry import DEFAULTS, merged

    ours = [n for n in filters if n in DEFAULTS]
    known = set().union(*(DEFAULTS[n] for n in ours)) if ours else set()
    if len(ours) == len(filters):
        for key in params:
            if key not in known:
                merged(ours[0], {key: params[key]})  # raises, naming the key and the known ones
    shares = {}
    for name in filters:
        if name in DEFAULTS:
            shares[name] = {k: v for k, v in params.items() if k in DEFAULTS[name]}
            merged(name, shares[name])
        else:
            shares[name] = {k: v for k, v in params.items() if k not in known}
    return shares


def run(args) -> int:
    from tqdm import tqdm

    from ..io import open_dataset, write_solution

    known = registry()
    filters = _check(args, known)
    shares = split_params(filters, parse_overrides(args.overrides))
    open_dataset(args.file).close()
    bar = tqdm(total=len(filters), unit="filter", desc="solve", leave=False, disable=args.quiet)
    for name in filters:
        bar.set_postfix_str(name)
        with open_dataset(args.file) as ds:
            sol = known[name](ds, shares[name], not args.quiet)
        write_solution(args.file, args.name or name, sol)
        bar.update()
        if not args.quiet:
            print(f"/solutions/{args.name or name}: {sol.t.size} epochs", file=sys.stderr)
    bar.close()
    return 0
