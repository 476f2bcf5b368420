"""``simkit solve FILE.h5 [--filter NAME ...] [--set estimator.key=value ...]``: estimators into /solutions.

Filter names come from ``simkit.estimators.SOLVERS`` (spp, kf15, kf15_dd, kf21, hinf) and, when that package exists, from
``simkit.attitude.SOLVERS``. Each writes ``/solutions/<name>`` (replacing only that group, atomically). Every
argument is checked (file, filter names, keys, every filter's values against :mod:`simkit.params` and the file)
before any filter runs: bad input is one line, exit 2, and the file is left as it was. A filter that then fails on
the file's data is reported in one line naming it and writes nothing; the other filters still run, and the exit
code is 1.
"""
from __future__ import annotations

import importlib
import importlib.util
import sys

from ..errors import ScenarioError, SimkitError
from ..params import check_against_file, merge, parse_set


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


def defaults_of(name: str) -> dict | None:
    """The parameter defaults of filter ``name``; None for a solver that declares none (it gets the ``--set``
    keys no declared filter knows, unchecked)."""
    from ..estimators.registry import DEFAULTS

    if name in DEFAULTS:
        return DEFAULTS[name]
    if importlib.util.find_spec("simkit.attitude.params") is None:
        return None
    from ..attitude.params import AMBIGUITY_DEFAULTS, TDCP_DEFAULTS
    from ..attitude.solvers import SOLVER_NAMES

    return TDCP_DEFAULTS if name == "tdcp" else AMBIGUITY_DEFAULTS if name in SOLVER_NAMES else None


def _check(args, known):
    filters = args.filters or ["spp", "kf15"]
    for name in filters:
        if name not in known:
            raise ScenarioError("--filter", f"unknown filter {name!r} (known: {', '.join(sorted(known))})")
    if args.name is not None:
        from ..io.solutions import _NAME

        if len(filters) != 1:
            raise ScenarioError("--name", "only valid with exactly one --filter")
        if not _NAME.match(args.name) or args.name.startswith("."):
            raise ScenarioError("--name", f"expected letters, digits, '_', '-' or '.' (not first), got {args.name!r}")
    return filters


def split_params(filters: list[str], params: dict) -> dict:
    """Each filter's share of the ``--set`` keys, every share checked (:func:`simkit.params.merge`) before any
    filter runs: a filter with declared defaults takes the keys it declares; one without takes the keys no
    declared filter knows. A key no requested filter can take is an error naming it."""
    declared = {name: defaults_of(name) for name in filters}
    known = set().union(*(d for d in declared.values() if d is not None))
    if all(d is not None for d in declared.values()):
        for key in params:
            if key not in known:  # raises, naming the key and the keys of the first filter
                merge(declared[filters[0]], {key: params[key]}, filters[0])
    shares = {}
    for name, defaults in declared.items():
        if defaults is None:
            shares[name] = {k: v for k, v in params.items() if k not in known}
        else:
            shares[name] = {k: v for k, v in params.items() if k in defaults}
            merge(defaults, shares[name], name)
    return shares


def _check_file(path, filters, shares) -> None:
    """The file opens as a simkit file, and each filter's values fit it (antenna index and count)."""
    from ..io import open_dataset

    with open_dataset(path) as ds:
        n_ant = ds["gnss/antennas/lever_arm_b"].shape[0] if "gnss/antennas/lever_arm_b" in ds else 0
    for name in filters:
        defaults = defaults_of(name)
        if defaults is not None:
            check_against_file(merge(defaults, shares[name], name), defaults, n_ant, path)


KERNEL_FILTERS = ("kf15", "kf15_dd", "kf21", "hinf")


def kernels_cold() -> bool:
    """True when a numba kernel of the filter loop (:mod:`simkit.estimators.loop`, which compiles the Kalman and
    H-infinity kernels it calls) has no valid on-disk cache yet: its first use compiles it, ~40 s of CPU. Reads
    numba's cache index; False when numba's layout is not the expected one."""
    from numba.core.dispatcher import Dispatcher

    from ..estimators import loop

    kernels = [f for f in vars(loop).values() if isinstance(f, Dispatcher)]
    try:
        return any(not f._cache._cache_file._load_index() for f in kernels)
    except (AttributeError, OSError):
        return False


def _solve_one(path, name, solver, share, progress):
    """(Solution, None) or (None, why) for one filter; a failure on the file's data is its one-line reason."""
    from ..io import open_dataset

    try:
        with open_dataset(path) as ds:
            return solver(ds, share, progress), None
    except SimkitError as exc:
        return None, str(exc)
    except (ValueError, ArithmeticError, IndexError, KeyError) as exc:  # np.linalg.LinAlgError is a ValueError
        return None, f"{type(exc).__name__}: {exc} (an internal error of the filter: please report it)"


def run(args) -> int:
    from tqdm import tqdm

    from ..io import write_solution

    known = registry()
    filters = _check(args, known)
    shares = split_params(filters, parse_set(args.overrides))
    _check_file(args.file, filters, shares)
    failed = []
    with tqdm(total=len(filters), unit="filter", desc="solve", leave=False, disable=args.quiet) as bar:
        if not args.quiet and any(n in KERNEL_FILTERS for n in filters) and kernels_cold():
            bar.write("solve: compiling the filter kernels (first run only, cached)", file=sys.stderr)
        for name in filters:
            bar.set_postfix_str(name)
            sol, why = _solve_one(args.file, name, known[name], shares[name], not args.quiet)
            if sol is None:
                failed.append(name)
                bar.write(f"simkit solve: {name}: failed: {why}", file=sys.stderr)
            else:
                write_solution(args.file, args.name or name, sol)
                if not args.quiet:
                    bar.write(f"/solutions/{args.name or name}: {sol.t.size} epochs", file=sys.stderr)
            bar.update()
    return 1 if failed else 0
