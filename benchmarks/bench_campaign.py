"""Campaign throughput: the same runs on Dask with 1 and 2 local workers (the speed-up), and on the standard
library's ProcessPoolExecutor with 2 processes (the peer: same task function, no Dask), in one process.

    python benchmarks/bench_campaign.py [--runs 16] [--duration 600]

Each run is a CPU-bound simulation of the xian_static_bds geometry (three antennas, BDS B1I at 1 Hz, IMU at
10 Hz) for --duration seconds plus its metrics (imu_errors, gnss_errors, single-epoch ILS ambiguity). The machine
load (1-minute load average) is printed before and after: on a shared 2-core machine the speed-up is bounded by
what the other users leave.
"""
from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from simkit.campaign import DEFAULT_METRICS, plan, run_campaign  # noqa: E402
from simkit.campaign.task import execute  # noqa: E402


def _dask(tmp: Path, name: str, runs: int, over: list[str], workers: int) -> float:
    t0 = time.perf_counter()
    s = run_campaign("xian_static_bds", tmp / name, runs, overrides=over, workers=workers)
    assert s["counts"]["completed"] == runs, s["failures"][:1]
    return time.perf_counter() - t0


def _pool(tmp: Path, runs: int, over: list[str], processes: int) -> float:
    run_dir = tmp / "pool" / "runs"
    run_dir.mkdir(parents=True)
    specs = plan("xian_static_bds", runs, overrides=over)
    t0 = time.perf_counter()
    with ProcessPoolExecutor(processes) as pool:
        recs = list(pool.map(execute, specs, [str(run_dir)] * runs, [DEFAULT_METRICS] * runs))
    assert all(r["status"] == "ok" for r in recs)
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=16)
    ap.add_argument("--duration", type=float, default=600.0, help="simulated seconds per run")
    a = ap.parse_args()
    over = [f"scenario.duration_s={a.duration:g}", f"trajectory.segment[0].duration_s={a.duration:g}"]
    load0 = os.getloadavg()[0]
    tmp = Path(tempfile.mkdtemp(prefix="bench_campaign_"))
    try:
        _dask(tmp, "warm", 2, over, 2)   # numba caches and imports warm for everyone
        t1 = _dask(tmp, "w1", a.runs, over, 1)
        t2 = _dask(tmp, "w2", a.runs, over, 2)
        tp = _pool(tmp, a.runs, over, 2)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"{a.runs} runs of xian_static_bds, {a.duration:g} s each, on {os.cpu_count()} cores; "
          f"load average {load0:.2f} before, {os.getloadavg()[0]:.2f} after")
    print(f"Dask, 1 worker : {t1:7.2f} s  ({a.runs / t1:.2f} runs/s)")
    print(f"Dask, 2 workers: {t2:7.2f} s  ({a.runs / t2:.2f} runs/s)   speed-up 1 -> 2 workers: {t1 / t2:.2f}x")
    print(f"peer ProcessPoolExecutor, 2 processes: {tp:7.2f} s  ({a.runs / tp:.2f} runs/s)   "
          f"Dask / peer time: {t2 / tp:.2f}")


if __name__ == "__main__":
    main()
