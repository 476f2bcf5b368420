"""Cold numba compile of the estimators: the first call of each filter kernel in a fresh process with an empty
numba cache (``NUMBA_CACHE_DIR`` pointed at a new temporary directory), then the same calls again in a second
process that loads the cache. Wall and CPU (process) seconds: on a shared machine the CPU time is the figure to
compare.

Each call runs on 2 s of synthetic static data (the benchmark data of ``bench_kf.py``), so the time is the
compile (or cache load) plus a few milliseconds of work. Run: python benchmarks/bench_compile.py
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import json, sys, time
t0, c0 = time.perf_counter(), time.process_time()
sys.path.insert(0, {root!r}); sys.path.insert(0, {bench!r})
import numpy as np
from bench_kf import CFG, data
from simkit.estimators import HInfinityFilter, KalmanFilter15, KalmanFilter21, strapdown
out = {{"import_s": time.perf_counter() - t0, "import_cpu_s": time.process_time() - c0}}
imu, gnss, init = data(2.0)
for name, call in (("kf15", lambda: KalmanFilter15(CFG, init).run(imu, gnss)),
                   ("hinf", lambda: HInfinityFilter(CFG, init).run(imu, gnss)),
                   ("kf21", lambda: KalmanFilter21(CFG, init).run(imu, gnss)),
                   ("strapdown", lambda: strapdown(imu.t, imu.gyro, imu.accel, pos0_lla=init.pos_lla,
                                                   vel0_enu=init.vel_enu, quat0_nb=init.quat_nb))):
    s, c = time.perf_counter(), time.process_time(); call()
    out[name + "_s"], out[name + "_cpu_s"] = time.perf_counter() - s, time.process_time() - c
out["total_s"], out["total_cpu_s"] = time.perf_counter() - t0, time.process_time() - c0
print(json.dumps({{k: round(v, 2) for k, v in out.items()}}))
"""


def run_child(cache_dir: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir, PYTHONPATH=str(ROOT))
    code = CHILD.format(root=str(ROOT), bench=str(ROOT / "benchmarks"))
    res = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main():
    with tempfile.TemporaryDirectory() as d:
        cold = run_child(d)
        warm = run_child(d)
    print(json.dumps({"cold": cold, "warm": warm, "load_average": os.getloadavg()[0]}, indent=1))


if __name__ == "__main__":
    main()
