"""The top-level API (re-exported as ``simkit.solve``, ``simkit.score``, ``simkit.validate``, ``simkit.campaign``).

The commands of the same names are argument parsing and printing around these calls. Every call checks all of
its input before computing anything; bad input raises a :class:`simkit.errors.SimkitError` (a ``ValueError``)
naming the argument, key or file and what was expected.
"""
from __future__ import annotations

import importlib
import importlib.util
import sys
import warnings

from .errors import ScenarioError, SimkitError
from .params import check_against_file, merge

DEFAULT_FILTERS = ("spp", "kf15")
KERNEL_FILTERS = ("kf15", "kf15_dd", "kf21", "hinf")


def registry() -> dict:
    """Every known filter name -> solver callable ``(ds, params, progress) -> Solution``: the estimators'
    ``SOLVERS`` and, when that package exists, ``simkit.attitude.SOLVERS``."""
    from .estimators import SOLVERS

    out = dict(SOLVERS)
    if importlib.util.find_spec("simkit.attitude") is not None:
        out.update(getattr(importlib.import_module("simkit.attitude"), "SOLVERS", {}))
    return out


def defaults_of(name: str) -> dict | None:
    """The parameter defaults of filter ``name``; None for a solver that declares none (it gets the parameters
    no declared filter knows, unchecked)."""
    from .estimators.registry import DEFAULTS

    if name in DEFAULTS:
        return DEFAULTS[name]
    if importlib.util.find_spec("simkit.attitude.params") is None:
        return None
    from .attitude.params import AMBIGUITY_DEFAULTS, TDCP_DEFAULTS
    from .attitude.solvers import SOLVER_NAMES

    return TDCP_DEFAULTS if name == "tdcp" else AMBIGUITY_DEFAULTS if name in SOLVER_NAMES else None


def check_filters(filters) -> list[str]:
    """``filters`` (None: :data:`DEFAULT_FILTERS`) as a list, each a known name (:func:`registry`)."""
    filters = list(filters) if filters is not None else list(DEFAULT_FILTERS)
    known = registry()
    for name in filters:
        if name not in known:
            raise ScenarioError("--filter", f"unknown filter {name!r} (known: {', '.join(sorted(known))})")
    return filters


def split_params(filters: list[str], params: dict) -> dict:
    """Each filter's share of ``params``, every share checked (:func:`simkit.params.merge`) before any filter
    runs: a filter with declared defaults takes the keys it declares; one without takes the keys no declared
    filter knows. A key no requested filter can take is an error naming it."""
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
    from .io import n_antennas, open_dataset

    with open_dataset(path) as ds:
        n_ant = n_antennas(ds)
    for name in filters:
        defaults = defaults_of(name)
        if defaults is not None:
            check_against_file(merge(defaults, shares[name], name), defaults, n_ant, path)


def check_solve(path, filters=None, params=None) -> dict:
    """Everything :func:`solve` checks before any filter runs; returns {filter name: its parameters}."""
    filters = check_filters(filters)
    shares = split_params(filters, dict(params or {}))
    _check_file(path, filters, shares)
    return shares


def kernels_cold(filters=None) -> bool:
    """True when a filter loop that ``filters`` (default: :func:`solve`'s) run has no valid on-disk cache yet:
    its first use compiles it, ~30 s of CPU. The Kalman and the H-infinity loops are two specialisations of
    :func:`simkit.estimators.loop.run` (its ``hinf`` argument is None or a bool). Reads numba's cache index; False
    when numba's layout is not the expected one."""
    from .estimators import loop

    wanted = {"bool" if n == "hinf" else "none" for n in set(check_filters(filters)) & set(KERNEL_FILTERS)}
    try:
        cached = {str(key[0][-1]) for key in loop.run._cache._cache_file._load_index()}
    except (AttributeError, OSError, EOFError, ValueError, IndexError, TypeError):
        return False
    return not wanted <= cached


# What `simkit compile` runs: the bundled quickstart (one antenna) and a 60 s Xi'an file (three antennas), each
# simulated and solved by every filter, so that the kernels of a first `simkit run` / `simkit solve` are compiled;
# the Xi'an file validated (`simkit validate`), and 5 s of urban_canyon (the ray tracer of an [environment])
_PREPARE = r"""
import tempfile, tomllib
from pathlib import Path
import simkit
from simkit.api import registry
xian = tomllib.loads((Path(simkit.__file__).parent / "scenarios" / "xian_static_bds.toml").read_text())
xian["scenario"]["duration_s"] = 60.0
for segment in xian["trajectory"]["segment"]:
    segment["duration_s"] = 60.0
with tempfile.TemporaryDirectory() as tmp:
    for name, scenario in (("quickstart", "quickstart"), ("xian", xian)):
        path = simkit.run(scenario, out=f"{tmp}/{name}.h5")
        simkit.solve(path, list(registry()), on_each=lambda *a: None)
    simkit.validate(path)
    simkit.run("urban_canyon", out=f"{tmp}/urban.h5", overrides=["scenario.duration_s=5"])
# the parallel broadcast-orbit kernel of large calls (a day of `simkit sky` or `simkit validate`)
import numpy as np
from simkit.constellation import kepler
n = kepler.PARALLEL_MIN_STATES
kepler.propagate(kepler.empty_table(1), np.full(n, -1), np.zeros(n), velocity=True)
"""


def prepare_cache(progress: bool = False):
    """Compile the kernels a first run needs and store them as the prepared cache (``simkit/_jit``,
    :mod:`simkit.jitcache`); returns (its path, number of files). Runs the work in a child process with its own
    empty numba cache; the new tree replaces the old one only once complete. Several minutes of CPU."""
    import os
    import shutil
    import subprocess
    import tempfile
    from pathlib import Path

    from numba.core.caching import UserProvidedCacheLocator

    from . import jitcache
    from .errors import OutputError

    target = jitcache.PREPARED
    if not jitcache.writable(target.parent):
        raise OutputError(str(target), "cannot be written: run `simkit compile` as the owner of the install")
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=str(Path(tmp) / "numba"))
        env["PYTHONPATH"] = os.pathsep.join([str(target.parents[1])] + [p for p in [env.get("PYTHONPATH")] if p])
        done = subprocess.run([sys.executable, "-c", _PREPARE], env=env, cwd=tmp,
                              stderr=None if progress else subprocess.DEVNULL, stdout=subprocess.DEVNULL)
        if done.returncode:
            raise SimkitError(f"simkit compile: the compile run failed (exit code {done.returncode})")
        new = Path(tempfile.mkdtemp(prefix="_jit.", dir=target.parent))
        count = 0
        for source_dir in sorted({p.parent for p in target.parent.rglob("*.py")} - {target}):
            sub = UserProvidedCacheLocator.get_suitable_cache_subpath(str(source_dir / "x.py"))
            for f in (Path(env["NUMBA_CACHE_DIR"]) / sub).glob("*.nb[ic]"):
                dst = new / source_dir.relative_to(target.parent) / f.name
                dst.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(f, dst)
                count += 1
        (new / "SOURCES").write_text(jitcache.sources_digest() + "\n")  # what the seeding checks
    old = target.with_name("_jit.old")
    shutil.rmtree(old, ignore_errors=True)
    if target.exists():
        target.rename(old)
    new.chmod(0o755)
    new.rename(target)
    shutil.rmtree(old, ignore_errors=True)
    return target, count


def _solve_one(path, solver, share, progress):
    """(Solution, None) or (None, why) for one filter; a failure on the file's data is its one-line reason."""
    from .io import open_dataset

    try:
        with open_dataset(path) as ds:
            return solver(ds, share, progress), None
    except SimkitError as exc:
        return None, str(exc)
    except (ValueError, ArithmeticError, IndexError, KeyError) as exc:  # np.linalg.LinAlgError is a ValueError
        return None, f"{type(exc).__name__}: {exc} (an internal error of the filter: please report it)"


def _warn_failure(name, solution, why) -> None:
    if solution is None:
        warnings.warn(f"simkit.solve: {name}: failed: {why}", RuntimeWarning, stacklevel=3)


def solve(path, filters=None, params=None, progress: bool = False, on_each=None) -> dict:
    """Run estimators on the simkit HDF5 file ``path``; returns {filter name: :class:`simkit.solution.Solution`}.

    ``filters``: names from :func:`registry` (estimators and attitude solvers; default ``spp`` and ``kf15``).
    ``params``: {key: value} (the keys of ``simkit solve --set estimator.KEY=VALUE``, e.g. ``{"gnss": "truth"}``),
    shared out by :func:`split_params` and checked with :mod:`simkit.params` against the file before any filter
    runs (bad input raises). The file is only read: ``simkit solve`` writes each solution with
    :func:`simkit.io.write_solution`. A filter that fails on the file's data is skipped (absent from the result)
    and reported: ``on_each(name, solution_or_None, why_or_None)`` is called after each filter in order; without
    it a failure is a ``RuntimeWarning``. ``progress``: a progress bar and the compile notice on stderr.
    """
    from tqdm import tqdm

    filters = check_filters(filters)
    shares, known = check_solve(path, filters, params), registry()
    report = on_each or _warn_failure
    out = {}
    with tqdm(total=len(filters), unit="filter", desc="solve", leave=False, disable=not progress) as bar:
        if progress and kernels_cold(filters):
            bar.write("solve: compiling the filter kernels (first run only, cached)", file=sys.stderr)
        for name in filters:
            bar.set_postfix_str(name)
            sol, why = _solve_one(path, known[name], shares[name], progress)
            if sol is not None:
                out[name] = sol
            report(name, sol, why)
            bar.update()
    return out


def score(path, estimate, spec=None, solution: str | None = None, point: str | None = None):
    """Errors of ``estimate`` against the truth of the simkit file ``path``: a :class:`simkit.referee.Score`.

    ``estimate``: a :class:`simkit.solution.Solution` (one of :func:`solve`'s, at the point it declares), a simkit
    HDF5 file with /solutions (``path`` itself is fine; ``solution`` names the group when there are several) or a
    CSV (columns: docs/referee.md; ``point``: ``imu``, ``antenna:K`` or ``lever_b:[x,y,z]``, body frame x right,
    y forward, z up, m). ``spec``: pass/fail thresholds, a TOML path or
    a :class:`simkit.referee.Spec` (``Score.passed``)."""
    return score_labelled(path, estimate, spec, solution, point)[0]


def score_labelled(path, estimate, spec=None, solution=None, point=None):
    """:func:`score` and the estimate's label (for the reports): ``(Score, str)``."""
    import numpy as np

    from . import referee
    from .referee.truth import truth_source

    if isinstance(spec, (str, bytes)) or hasattr(spec, "__fspath__"):
        spec = referee.load_spec(spec)
    from .solution import Solution

    if isinstance(estimate, Solution):
        if solution is not None or point is not None:
            raise ScenarioError("solution/point", "only for an estimate read from a file; a Solution declares its "
                                                  "own point")
        sol, label = estimate, "solution"
    else:
        sol, label = referee.load_estimate(estimate, solution, referee.file_start(path), point)
    finite = np.asarray(sol.t, dtype=float)[np.isfinite(sol.t)]
    span = (finite.min(), finite.max()) if finite.size else (None, None)
    truth = referee.read_truth(path, *span)    # only the truth the estimate needs
    source = truth_source(path)
    if source.startswith("/reference") and (sol.quat_nb is not None or sol.euler is not None):
        raise ScenarioError(str(estimate if sol is not estimate else label),
                            f"has an attitude, but {path} has no /truth, only a reference position: "
                            "its attitude cannot be scored")
    sc = referee.score(truth, sol, spec, where=str(label if sol is estimate else estimate), path=path)
    sc.meta["truth"] = source
    return sc, label


def check_validate(n_random: int, random_stride: int) -> None:
    """The counts of :func:`validate`, named by their command-line options."""
    if n_random < 0:
        raise ScenarioError("--random", f"found {n_random}; expected a count >= 0")
    if random_stride < 1:
        raise ScenarioError("--random-stride", f"found {random_stride}; expected an epoch step >= 1")


def _geometry(scenario_or_path, overrides):
    from pathlib import Path

    from .errors import OutputError
    from .io import open_dataset
    from .scenario import load
    from .validation import geometry

    path = Path(scenario_or_path) if isinstance(scenario_or_path, (str, Path)) else None
    if path is not None and path.suffix.lower() in (".h5", ".hdf5"):
        if overrides:
            raise ScenarioError("--set", "applies to a scenario input, not to an HDF5 file")
        if not path.is_file():
            raise OutputError(path, "no such file")
        with open_dataset(path) as ds:
            return geometry.from_file(ds)
    return geometry.from_scenario(load(scenario_or_path, overrides or []))


def validate(scenario_or_path, overrides=None, systems: str | None = None, *, n_random: int = 1,
             random_stride: int = 10, **options):
    """Wang 2018's observability claims C1-C7 on a scenario (a TOML path, bundled name or dict: geometry only,
    no file written) or a simkit HDF5 file: a :class:`simkit.validation.summary.Validation` (``.summary`` the
    JSON of ``simkit validate``, ``.mathematical_failure`` True when C1-C5 fail somewhere).

    ``overrides``: scenario ``--set`` items (scenario input only); ``systems``: RINEX letters, comma-separated;
    ``n_random`` random orderings at every ``random_stride``-th epoch; ``options``: ``weighting`` (``dd`` or
    ``identity``), ``seed``, ``progress`` of :func:`simkit.validation.summary.validate`."""
    from .validation import geometry
    from .validation.summary import validate as _validate

    check_validate(n_random, random_stride)
    geo = _geometry(scenario_or_path, overrides)
    if systems:
        geo = geometry.select_systems(geo, systems)
    return _validate(geo, n_random=n_random, random_stride=random_stride, **options)


def campaign(scenario, out, runs: int, **options) -> dict:
    """Monte Carlo runs of ``scenario`` into the folder ``out`` (one HDF5 file per run in ``out/runs``): the
    summary also written to ``out/summary.json``. ``options``: ``grid``, ``overrides``, ``first_seed``,
    ``workers`` or ``scheduler``, ``metrics`` (None: :data:`simkit.campaign.DEFAULT_METRICS`), ``progress``,
    ``confidence`` of :func:`simkit.campaign.run_campaign`. A re-run skips the runs already complete.
    ``simkit.campaign`` is the sub-package, made callable as this function."""
    from .campaign import run_campaign

    return run_campaign(scenario, out, runs, **options)


def export(path, fmt: str, out, **options) -> list:
    """Write the simkit file ``path`` as ``fmt`` ("rosbag2", "csv" or "kml") at ``out``; returns the written paths
    (:func:`simkit.export.export`, its options; docs/logs_and_export.md)."""
    from .export import export as _export

    return _export(path, fmt, out, **options)
