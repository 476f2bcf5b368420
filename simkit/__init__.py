"""simkit: multi-antenna GNSS/INS simulation with exact truth, and the tools that check what consumes it."""
from __future__ import annotations

from .version import __version__

__all__ = ["__version__", "open", "run"]


def run(scenario, out=None, seed=None, overrides=None, progress=False, force=False, threads=None):
    """Simulate ``scenario`` (a TOML path, a bundled name or a dict) into an HDF5 file; returns its Path.

    ``threads``: threads compressing the output (1: on the calling thread; default ``$SIMKIT_NUM_THREADS``, else
    up to 4, one per core)."""
    from .pipeline import run as _run

    return _run(scenario, out=out, seed=seed, overrides=overrides, progress=progress, force=force, threads=threads)


def open(path):  # noqa: A001 - the documented API name
    """Open a simkit HDF5 file lazily (see :class:`simkit.io.reader.Dataset`)."""
    from .io.reader import open_dataset

    return open_dataset(path)
