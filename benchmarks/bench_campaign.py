"""Campaign throughput: the same runs on Dask with 1 and 2 local workers (the speed-up), and on the standard
library's ProcessPoolExecutor with 2 processes (the peer: same task function, no Dask), in one process.

    python benchmarks/bench_campaign.py [--runs 16] [--duration 600]

Each run is a CPU-bound simulation of the xian_static_bds geometry (three antennas, BDS B1I at 1 Hz, IMU at
10 Hz) for --duration seconds plus its metrics (imu_errors, gnss_errors, single-epoch ILS ambiguity). The machine
load (1-minute load average) is printed before and after: on a shared 2-core machine the speed-up is bounded by
what the other users leave. Both pools are warmed first (one run per process: imports, numba caches), so the
figures compare steady-state throughput; both spawn fresh interpreters.
"""
from __future__ import annotations

import os

# one BLAS / OpenMP thread per process, set before numpy loads: Dask's nanny does the same for its workers
# (distributed.nanny.pre-spawn-environ), so the process-pool peer started from here runs under the same rule
for _var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import logging  # noqa: E402
import multiprocessing  # noqa: E402
import shutil  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from concurrent.futures import ProcessPoolExecutor  # noqa: E402
from pathlib import Path  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from simkit.campaign import DEFAULT_METRICS, plan, run_campaign  # noqa: E402
from simkit.campaign.runner import local_cluster  # noqa: E402
from simkit.campaign.task import execute  # noqa: E402


def _dask(tmp: Path, runs: int, over: list[str], workers: int) -> float:
    """Campaign time on a warm local cluster of ``workers`` processes, built as ``simkit campaign`` builds it
    (start-up and first imports excluded)."""
    with local_cluster(workers, silence_logs=logging.ERROR) as cluster:
        address = cluster.scheduler_address
        run_campaign("xian_static_bds", tmp / f"warm{workers}", workers, first_seed=10**6, overrides=over,
                     scheduler=address)
        t0 = time.perf_counter()
        s = run_campaign("xian_static_bds", tmp / f"w{workers}", runs, overrides=over, scheduler=address)
        elapsed = time.perf_counter() - t0
    assert s["counts"]["completed"] == runs, s["failures"][:1]
    return elapsed


def _pool(tmp: Path, runs: int, over: list[str], processes: int) -> float:
    """The same task function on a warm ProcessPoolExecutor."""
    run_dir = tmp / "pool" / "runs"
    run_dir.mkdir(parents=True)
    warm = plan("xian_static_bds", processes, first_seed=10**6, overrides=over)
    specs = plan("xian_static_bds", runs, overrides=over)
    # spawned like Dask's workers: forking a process that already ran OpenMP threads (numba) is unsafe
    with ProcessPoolExecutor(processes, mp_context=multiprocessing.get_context("spawn")) as pool:
        list(pool.map(execute, warm, [str(run_dir)] * processes, [DEFAULT_METRICS] * processes))
        t0 = time.perf_counter()
        recs = list(pool.map(execute, specs, [str(run_dir)] * runs, [DEFAULT_METRICS] * runs))
        elapsed = time.perf_counter() - t0
    assert all(r["status"] == "ok" for r in recs)
    return elapsed


def measure(runs: int = 16, duration: float = 600.0, repeat: int = 2) -> dict:
    """Best of ``repeat`` interleaved rounds (a load change hits all three alike): Dask 1 and 2 workers, the pool."""
    over = [f"scenario.duration_s={duration:g}", f"trajectory.segment[0].duration_s={duration:g}"]
    load0 = os.getloadavg()[0]
    tmp = Path(tempfile.mkdtemp(prefix="bench_campaign_"))
    try:
        times = []
        for k in range(repeat):
            round_dir = tmp / f"round{k}"
            round_dir.mkdir()
            times.append((_dask(round_dir, runs, over, 1), _dask(round_dir, runs, over, 2),
                          _pool(round_dir, runs, over, 2)))
        t1, t2, tp = (min(col) for col in zip(*times))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return {"runs": runs, "duration_s": duration, "repeat": repeat, "one_worker_s": t1, "two_workers_s": t2,
            "pool_s": tp, "load_before": load0, "load_after": os.getloadavg()[0], "cores": os.cpu_count()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=16)
    ap.add_argument("--duration", type=float, default=600.0, help="simulated seconds per run")
    ap.add_argument("--repeat", type=int, default=2, help="rounds of the three measurements, best of each kept")
    a = ap.parse_args()
    r = measure(a.runs, a.duration, a.repeat)
    t1, t2, tp = r["one_worker_s"], r["two_workers_s"], r["pool_s"]
    print(f"best of {a.repeat} interleaved rounds; {a.runs} runs of xian_static_bds, {a.duration:g} s each, "
          f"on {r['cores']} cores; load average {r['load_before']:.2f} before, {r['load_after']:.2f} after")
    print(f"Dask, 1 worker : {t1:7.2f} s  ({a.runs / t1:.2f} runs/s)")
    print(f"Dask, 2 workers: {t2:7.2f} s  ({a.runs / t2:.2f} runs/s)   speed-up 1 -> 2 workers: {t1 / t2:.2f}x")
    print(f"peer ProcessPoolExecutor, 2 processes: {tp:7.2f} s  ({a.runs / tp:.2f} runs/s)   "
          f"Dask / peer time: {t2 / tp:.2f}")


if __name__ == "__main__":
    main()
