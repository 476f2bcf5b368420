"""Per-solve time of simkit.ambiguity.ils vs RTKLIB's C lambda (pyrtklib) and cssrlib's Python mlambda.

Run: python benchmarks/bench_lambda.py. Same random problems (studies.ambiguity_problems.random_problem, "well"
conditioned, i.e. GNSS-like after a few epochs) for every solver; RTKLIB is timed on pre-filled buffers; medians
over problems of the per-problem mean time. The compiled kernel is timed (see simkit/ambiguity/warmup.py; the
cold start is benchmarks/bench_cold_start.py).
"""
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # this checkout, and its studies/
from simkit.ambiguity import ils  # noqa: E402
from simkit.ambiguity.warmup import wait_for_jit  # noqa: E402
from studies.ambiguity_problems import random_problem  # noqa: E402


def _time(fn, reps):
    t = time.perf_counter()
    for _ in range(reps):
        fn()
    return (time.perf_counter() - t) / reps


def measure(sizes=(10, 20, 40), n_problems=30):
    """[(n, simkit us, RTKLIB C us, cssrlib us)]: medians over ``n_problems`` problems of each size (cssrlib NaN
    when it is not installed)."""
    import pyrtklib

    try:
        from cssrlib.mlambda import mlambda
    except ImportError:
        mlambda = None

    rtk = getattr(pyrtklib, "lambda")
    ils(np.zeros(3), np.eye(3))
    wait_for_jit()  # time the compiled kernel, not the interpreted one that answers while numba compiles
    devnull = os.open(os.devnull, os.O_WRONLY)
    saved = os.dup(2)
    rows = []
    for n in sizes:
        rng = np.random.default_rng(n)
        ts, tr, tc = [], [], []
        A = pyrtklib.Arr1Ddouble
        ab, Qb, F, s = A(n), A(n * n), A(2 * n), A(2)
        for _ in range(n_problems):
            a, Q, _ = random_problem(rng, n, "well")
            ils(a, Q)
            ts.append(_time(lambda: ils(a, Q, n_cands=2), 200))
            for i, v in enumerate(a.tolist()):
                ab[i] = v
            for i, v in enumerate(Q.T.ravel().tolist()):
                Qb[i] = v
            os.dup2(devnull, 2)  # RTKLIB prints loop-count overflows to C stderr
            try:
                tr.append(_time(lambda: rtk(n, 2, ab, Qb, F, s), 200))
            finally:
                os.dup2(saved, 2)
            if mlambda is not None:
                tc.append(_time(lambda: mlambda(a, Q, 2), 2 if n >= 20 else 5))
        rows.append((n, *(float(np.median(x) * 1e6) if x else float("nan") for x in (ts, tr, tc))))
    return rows


def main(sizes=(10, 20, 40), n_problems=30):
    print(f"{'n':>3} {'simkit us':>10} {'RTKLIB C us':>12} {'cssrlib us':>11} {'simkit/C':>9} {'cssrlib/simkit':>15}")
    for n, ms, mr, mc in measure(sizes, n_problems):
        print(f"{n:>3} {ms:>10.1f} {mr:>12.1f} {mc:>11.0f} {ms / mr:>9.2f} {mc / ms:>15.0f}")


if __name__ == "__main__":
    main()
