"""A/B timing of simkit.ambiguity.ils between two checkouts (e.g. before and after a change), tight enough to see
a few per cent: each tree runs in its own interpreter, alternating, ``--rounds`` times; per problem the best of
7 x 100 calls, then the median over 20 "well"-conditioned random problems per size.

    git worktree add /tmp/before <rev>; python benchmarks/bench_lambda_ab.py /tmp/before .

(bench_lambda.py gives the ratio to RTKLIB's C in the same run, with more per-run noise: docs/benchmarks.md.)
"""
from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import timing  # noqa: E402  (benchmarks/timing.py: the A/B runner)

PROBE = r"""
import sys, time, numpy as np
sys.path.insert(0, sys.argv[1])
sys.path.append(sys.argv[2])  # the problems of this checkout's studies/, the same for both trees
from simkit.ambiguity import ils
from studies.ambiguity_problems import random_problem
try:
    from simkit.ambiguity.warmup import wait_for_jit
except ImportError:
    def wait_for_jit():
        pass
ils(np.zeros(3), np.eye(3)); wait_for_jit()

def best_us(fn, reps=100):
    fn(); best = 1e9
    for _ in range(7):
        t = time.perf_counter()
        for _ in range(reps):
            fn()
        best = min(best, (time.perf_counter() - t) / reps * 1e6)
    return best

row = []
for n in (10, 20, 40):
    rng = np.random.default_rng(n)
    row.append(np.median([best_us(lambda: ils(a, Q, n_cands=2))
                          for a, Q, _ in (random_problem(rng, n, "well") for _ in range(20))]))
print(" ".join(f"{x:.1f}" for x in row))
"""


def main(argv=None) -> int:
    return timing.ab_main(__doc__, PROBE, ["n=10 us", "n=20 us", "n=40 us"], argv, ROOT)


if __name__ == "__main__":
    sys.exit(main())
