"""Running a campaign on Dask: a local cluster of processes by default, an existing scheduler when given.

Workers must see ``DIR`` at the same path (one machine, or a shared file system) and import the same simkit.
Each run is one task (:func:`simkit.campaign.task.execute`); the client verifies completed runs by content
before submitting anything, collects records as tasks finish (progress bar), records the runs whose task was
lost, and writes ``DIR/summary.json`` atomically at the end.
"""
from __future__ import annotations

import contextlib
import logging
import signal
import threading
import time
import uuid
from pathlib import Path

from ..errors import SimkitError
from ..version import __version__
from .aggregate import run_table, summarise
from .errors import CampaignInputError
from .metrics import DEFAULT_METRICS, get
from .plan import RunSpec, expected_text, parse_grid, plan
from .index import write_index
from .records import file_digest, file_identity, read_record, record_path, verify, write_json_atomic
from .task import execute, failed_record

SUMMARY_VERSION = 1
CONNECT_TIMEOUT_S = 10.0  # how long --scheduler is tried before the error


@contextlib.contextmanager
def dask_client(workers: int | None = None, scheduler: str | None = None,
                connect_timeout_s: float | None = None):
    """A ``distributed.Client``: to ``scheduler`` (``tcp://host:port``), or to a new local cluster of ``workers``
    single-threaded processes (default 2) listening on loopback only (random ports), closed on exit."""
    try:
        from distributed import Client
    except ImportError:
        raise CampaignInputError("campaign", "needs dask and distributed: pip install 'simkit[campaign]'") from None
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=connect_timeout_s or CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError, ValueError) as exc:
            raise CampaignInputError("--scheduler", f"{scheduler}: cannot connect ({exc}); expected the address "
                                     "of a running `dask scheduler`, e.g. tcp://127.0.0.1:8786") from None
        with client:
            yield client
        return
    with _sigint_ignored():
        cluster = local_cluster(workers or 2)
    with cluster, Client(cluster) as client:
        yield client


def local_cluster(workers: int, silence_logs: int = logging.CRITICAL):
    """A Dask ``LocalCluster`` of ``workers`` single-threaded processes on loopback (random ports), as campaigns
    use it. The workers' statistical profiler is off: it samples the run's thread every 10 ms and took 5-10 % of a
    worker's CPU (0.1-0.2 s per 4 s of runs, measured with thread against process CPU time), which on a machine
    with one worker per core comes out of the runs. CRITICAL logs by default: a run's failure reaches the campaign
    through its future (and its triage), while Dask's own ERROR lines are the local cluster's teardown noise (a
    worker's heartbeat to a scheduler closed by Ctrl-C)."""
    import dask
    from distributed import LocalCluster

    with dask.config.set({"distributed.worker.profile.enabled": False}):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                            scheduler_port=0, dashboard_address="127.0.0.1:0", silence_logs=silence_logs)


@contextlib.contextmanager
def _sigint_ignored():
    """SIGINT ignored while the local workers start, so that they inherit the ignored disposition: a Ctrl-C in
    the terminal (sent to every process of the group) then stops this process alone, which closes the cluster,
    instead of each worker dying with a page of heartbeat tracebacks. Outside the main thread: no change."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def triage(specs, run_dir: Path, metric_names) -> tuple[dict, list]:
    """Split the plan into verified records that need nothing ({run_id: record}) and work to submit
    [(spec, previous, text)]: previous is a verified record that only lacks some metrics (else None), text the
    effective scenario the run's file must carry."""
    done, todo = {}, []
    for spec in specs:
        rec = read_record(record_path(run_dir, spec.run_id))
        text = expected_text(spec)
        if verify(rec, run_dir / f"{spec.run_id}.h5", text, spec.seed) is None:
            if all(m in rec.get("metrics", {}) for m in metric_names):
                done[spec.run_id] = rec
            else:
                todo.append((spec, rec, text))
        else:
            todo.append((spec, None, text))
    return done, todo


def refuse_other_settings(specs, run_dir: Path) -> None:
    """A completed run in ``run_dir`` under a planned run's name that belongs to other settings (its record has
    another seed or --set/--grid, or its intact file another effective scenario) is refused before anything is
    written: a re-run would replace it. A file that differs from its own record (tampered, swapped) is not a
    campaign's result and is run again, as before."""
    for spec in specs:
        rec, h5 = read_record(record_path(run_dir, spec.run_id)), run_dir / f"{spec.run_id}.h5"
        if rec is None or rec.get("status") != "ok" or not h5.is_file():
            continue
        other = str(rec.get("seed")) != str(spec.seed) or list(rec.get("overrides", [])) != list(spec.overrides)
        if not other:
            try:
                other = file_identity(h5)[0] != expected_text(spec) and file_digest(h5) == rec.get("sha256")
            except SimkitError:
                continue  # unreadable: an incomplete run, run again as before
        if other:
            raise CampaignInputError("-o", f"{run_dir.parent}: holds a campaign with other settings (run "
                                     f"{spec.run_id} has another scenario, --set, --grid or seed); use another "
                                     "folder, or remove that one")


def _collect(client, todo, run_dir: Path, metric_names, progress: bool) -> dict:
    from distributed import as_completed

    tag = uuid.uuid4().hex[:8]
    futures = {client.submit(execute, spec, str(run_dir), tuple(metric_names), prev, text, pure=False,
                             key=f"simkit-run-{spec.run_id}-{tag}"): spec for spec, prev, text in todo}
    records = {}
    bar = _bar(len(futures), progress)
    try:
        for fut in as_completed(futures):
            spec = futures[fut]
            try:
                records[spec.run_id] = fut.result()
            except Exception as exc:  # the worker died too often, or the task was lost: record it, go on
                records[spec.run_id] = failed_record(spec, exc)
                write_json_atomic(record_path(run_dir, spec.run_id), records[spec.run_id])
            bar.update(1)
    finally:
        bar.close()
        client.cancel(list(futures))
    return records


def _bar(total: int, progress: bool):
    from tqdm import tqdm

    return tqdm(total=total, unit="run", desc="campaign", disable=not progress, leave=False)


def check_dir(out_dir) -> Path:
    """The campaign directory ``DIR`` (not created here): a clear error when it is a file or its parent is
    missing. Absolute, since workers run in other folders (or on other machines sharing the file system)."""
    from ..io.output import check_output

    return check_output(Path(out_dir).absolute(), option="-o", folder=True)


def run_campaign(scenario, out_dir, runs: int, grid=(), overrides=(), first_seed: int = 0, workers=None,
                 scheduler=None, metrics=DEFAULT_METRICS, progress: bool = False,
                 confidence: float = 0.95) -> dict:
    """Run (or complete) a campaign into ``out_dir``; returns the summary also written to ``summary.json``.

    ``grid``: ["dotted.key=v1,v2", ...] (TOML literals, as ``--set``); ``runs`` seeds per grid point, from
    ``first_seed``; ``overrides`` apply to every run; ``metrics`` registry names or ``module:function`` (None: the defaults).
    """
    t0 = time.perf_counter()
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise CampaignInputError("--workers", f"expected a positive integer, got {workers!r}")
    if not 0.0 < confidence < 1.0:
        raise CampaignInputError("--confidence", f"expected a number in (0, 1), got {confidence!r}")
    metrics = tuple(DEFAULT_METRICS if metrics is None else metrics)
    for name in metrics:
        get(name)
    specs = plan(scenario, runs, grid, first_seed, overrides)
    out = check_dir(out_dir)
    refuse_other_settings(specs, out / "runs")
    done, todo = triage(specs, out / "runs", metrics)
    records = dict(done)
    if todo:
        with dask_client(workers, scheduler) as client:  # connect before creating anything on disk
            (out / "runs").mkdir(parents=True, exist_ok=True)
            records.update(_collect(client, todo, out / "runs", metrics, progress))
    summary = _summary(specs, records, scenario, runs, grid, overrides, first_seed, metrics, confidence)
    summary["counts"]["skipped"] = len(done)
    summary["elapsed_s"] = time.perf_counter() - t0
    summary["cluster"] = scheduler or f"local, {workers or 2} worker processes"
    summary["index"] = {"file": "index.h5", "stacked": len(write_index(out, summary["runs"], records))}
    write_json_atomic(out / "summary.json", summary)
    return summary


def _summary(specs: list[RunSpec], records, scenario, runs, grid, overrides, first_seed, metrics, confidence):
    points, failures = summarise(specs, records, confidence)
    completed = sum(1 for r in records.values() if r.get("status") == "ok")
    return {"summary_version": SUMMARY_VERSION, "simkit_version": __version__, "scenario": str(scenario),
            "runs_per_point": runs, "first_seed": first_seed, "overrides": list(overrides),
            "grid": {k: v for k, v in parse_grid(grid)}, "metrics": list(metrics), "confidence": confidence,
            "counts": {"planned": len(specs), "completed": completed, "failed": len(failures)},
            "points": points, "failures": failures, "runs": run_table(specs, records)}
