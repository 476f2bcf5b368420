"""simkit: multi-antenna GNSS/INS simulation with exact truth, and the tools that check what consumes it."""
from __future__ import annotations

from . import jitcache
from .version import __version__

# when numba loads, before any kernel is defined: a cache directory even in a read-only install (jitcache.choose),
# seeded from the prepared cache (`simkit compile`), content-keyed
jitcache.register_when_numba_loads()

__all__ = ["__version__", "campaign", "open", "run", "score", "solve", "validate"]


def run(scenario, out=None, seed=None, overrides=None, progress=False, force=False, threads=None):
    """Simulate ``scenario`` (a TOML path, a bundled name or a dict) into an HDF5 file; returns its Path.

    ``threads``: threads sharing the work, the calling thread included (1: all of it on the calling thread;
    default ``$SIMKIT_NUM_THREADS``, else up to 4, one per core)."""
    from .pipeline import run as _run

    return _run(scenario, out=out, seed=seed, overrides=overrides, progress=progress, force=force, threads=threads)


def open(path):  # noqa: A001 - the documented API name
    """Open a simkit HDF5 file lazily (see :class:`simkit.io.dataset.Dataset`)."""
    from .io.dataset import open_dataset

    return open_dataset(path)


def solve(path, filters=None, params=None, progress=False, on_each=None):
    """Run estimators on a simkit file: {filter name: Solution}; the file is only read (:func:`simkit.api.solve`)."""
    from .api import solve as _solve

    return _solve(path, filters=filters, params=params, progress=progress, on_each=on_each)


def score(path, estimate, spec=None, solution=None, point=None):
    """Errors of an estimate against the file's truth: a ``simkit.referee.Score`` (:func:`simkit.api.score`)."""
    from .api import score as _score

    return _score(path, estimate, spec=spec, solution=solution, point=point)


def validate(scenario_or_path, **options):
    """Wang 2018's observability claims on a scenario or a file (:func:`simkit.api.validate`, its options)."""
    from .api import validate as _validate

    return _validate(scenario_or_path, **options)


def __getattr__(name):
    """``simkit.campaign``: the campaign sub-package, callable as :func:`simkit.api.campaign` (imported on first
    use: importing a sub-package rebinds its name in this package, so a function of that name would not stay)."""
    if name == "campaign":
        import importlib

        return importlib.import_module(".campaign", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
