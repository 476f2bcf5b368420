"""A/B timing of the filter loop (kf15 and hinf) between two checkouts, warm numba cache: each tree runs in its
own interpreter with its own ``NUMBA_CACHE_DIR`` (compiled by a first, untimed run), alternating, ``--rounds``
times; each child runs each filter once to load the kernels, then 3 times on 1 h of 100 Hz IMU data with 1 Hz
fixes (``bench_kf.data``, of this checkout for both trees) and prints the best CPU seconds (``time.process_time``).

    git worktree add /tmp/before <rev>; python benchmarks/bench_kf_ab.py /tmp/before .
"""
from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import timing  # noqa: E402  (benchmarks/timing.py: the A/B runner)

PROBE = r"""
import sys, time
sys.path.insert(0, sys.argv[1]); sys.path.append(sys.argv[2])
from simkit.estimators import HInfinityFilter, KalmanFilter15  # the tree's, before bench_kf puts this checkout first
from bench_kf import CFG, data
imu, gnss, init = data(3600.0)
row = []
for F in (KalmanFilter15, HInfinityFilter):
    F(CFG, init).run(imu, gnss)
    best = 1e9
    for _ in range(3):
        c = time.process_time()
        F(CFG, init).run(imu, gnss)
        best = min(best, time.process_time() - c)
    row.append(best)
print(" ".join(f"{x:.3f}" for x in row))
"""


def main(argv=None) -> int:
    return timing.ab_main(__doc__, PROBE, ["kf15 CPU s", "hinf CPU s"], argv, ROOT / "benchmarks", own_cache=True)


if __name__ == "__main__":
    sys.exit(main())
