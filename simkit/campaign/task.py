"""What a Dask worker does for one run: simulate it, compute its metrics, and write its record.

The HDF5 file is written atomically by :func:`simkit.pipeline.run` (a hidden temporary renamed when complete;
the temporary of a killed worker is removed by the next run to the same name), then the record is written
atomically, so a run is either complete on disk or absent, never half-written.
"""
from __future__ import annotations

import contextlib
import functools
import os
import socket
import time
from pathlib import Path

import numba

from ..heap import keep_freed_memory
from ..io import open_dataset
from ..pipeline import run as simulate
from .metrics import evaluate
from .plan import RunSpec
from .records import RECORD_VERSION, file_digest, read_record, record_path, verify, write_json_atomic


TRIM_THRESHOLD_BYTES = 256 << 20


@functools.cache
def tune_worker_process() -> bool:
    """Once per process: make a run behave as it does outside Dask, on one thread. Returns True if glibc took the
    allocator settings.

    - Dask's nanny starts workers with ``MALLOC_TRIM_THRESHOLD_=65536`` (to hand memory back to the OS early).
      That also freezes glibc's mmap threshold at 128 KiB, so every block of a run allocates its large temporaries
      with fresh ``mmap`` calls and page-faults them in again: a run took 1.7x as long inside a worker as in a
      plain process (xian_static_bds, 1 h: 0.85 s against 0.50 s). A large trim threshold and the 64-bit maximum
      mmap threshold bring it back to 0.50 s. Memory stays bounded: a run writes in blocks, so its peak is what it
      is outside Dask. Other C libraries (musl, macOS) have no such setting and are left alone.
    """
    return keep_freed_memory(TRIM_THRESHOLD_BYTES, override_env=True)  # the nanny's tunable is what this undoes


@contextlib.contextmanager
def one_thread():
    """numba's parallel kernels on one thread for the calling thread, restored on exit.

    The runs are the parallelism of a campaign (one worker per core), so a run keeps to its own thread: its output
    is compressed on it too (``threads=1``); the gain is in docs/benchmarks.md.
    """
    previous = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(previous)


def base_record(spec: RunSpec) -> dict:
    """The fields every record of ``spec`` carries."""
    return {"record_version": RECORD_VERSION, "run_id": spec.run_id, "seed": spec.seed, "point": spec.point,
            "overrides": list(spec.overrides), "file": f"{spec.run_id}.h5"}


def execute(spec: RunSpec, run_dir: str, metric_names: tuple[str, ...], previous: dict | None = None,
            text: str | None = None) -> dict:
    """Run ``spec`` into ``run_dir/<run_id>.h5`` and evaluate ``metric_names`` on it; returns the record (also
    written to ``run_dir/<run_id>.json``). With ``previous`` (the verified record of a completed run) the file is
    kept and only the metrics it lacks are computed. With ``text`` (the expected effective scenario) a run found
    complete on disk is returned as it is: Dask recomputes a task whose result died with its worker before the
    client fetched it, and that must not rewrite a finished run. Any exception becomes a "failed" record."""
    tune_worker_process()
    run_dir = Path(run_dir)
    h5 = run_dir / f"{spec.run_id}.h5"
    if previous is None and text is not None:
        found = read_record(record_path(run_dir, spec.run_id))
        if verify(found, h5, text, spec.seed) is None and all(m in found.get("metrics", {}) for m in metric_names):
            return found
    t0 = time.perf_counter()
    rec = base_record(spec)
    try:
        if previous is None:
            with one_thread():
                simulate(spec.scenario, out=h5, seed=spec.seed, overrides=list(spec.overrides), threads=1)
            metrics = {}
        else:
            metrics = dict(previous.get("metrics", {}))
        with one_thread(), open_dataset(h5) as ds:
            metrics.update(evaluate(ds, [m for m in metric_names if m not in metrics]))
            layout = dataset_layout(ds)
        rec.update(status="ok", sha256=previous["sha256"] if previous else file_digest(h5), metrics=metrics,
                   elapsed_s=(previous or {}).get("elapsed_s", time.perf_counter() - t0), datasets=layout)
    except Exception as exc:  # recorded, never fatal to the campaign
        rec.update(status="failed", error=f"{type(exc).__name__}: {exc}", elapsed_s=time.perf_counter() - t0)
    rec["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    write_json_atomic(record_path(run_dir, spec.run_id), rec)
    return rec


def dataset_layout(ds) -> dict:
    """path -> [shape, dtype str] of the file's numeric datasets, in file order: the campaign index stacks the runs
    from the records, so the client does not walk every run file after the last run (0.2 s for 12 runs)."""
    return {path: [list(arr.shape), arr.dtype.str] for path, arr in ds.datasets() if arr.dtype.kind != "O"}


def failed_record(spec: RunSpec, error: BaseException) -> dict:
    """The record of a run whose task never returned (its worker died too often, the task was lost)."""
    rec = base_record(spec)
    rec.update(status="failed", error=f"{type(error).__name__}: {error}", elapsed_s=None, worker=None)
    return rec
