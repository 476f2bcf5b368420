"""Ambiguity-to-attitude speed: a 24 h, 1 Hz, three-antenna file (xian_static_bds) solved by
``simkit.attitude.SOLVERS["attitude"]`` (read, DD float solution, LAMBDA with ratio test, attitude with
covariance), and the ambiguity step alone against RTKLIB's C ``lambda`` (pyrtklib) on the same float problems.

Run: python benchmarks/bench_attitude.py [FILE.h5]   (without FILE the 24 h scenario is simulated first, ~40 s)
RTKLIB is timed per call on pre-filled buffers (filling them from Python is not counted); simkit's ambiguity
step is ``ils_batch`` on the same problems, grouped by channel pattern as the solver does.
"""
import os
import sys
import tempfile
import time

import numpy as np

import simkit
from simkit import ambiguity as amb
from simkit.attitude import SOLVERS, float_solution
from simkit.attitude.params import AMBIGUITY_DEFAULTS, merge
from simkit.attitude.reading import read


def _rtklib_seconds(groups, stride=1):
    """Sum over epochs of RTKLIB lambda's call time (2 candidates), and the fraction of epochs it solved."""
    import pyrtklib

    rtk = getattr(pyrtklib, "lambda")
    devnull, saved = os.open(os.devnull, os.O_WRONLY), os.dup(2)
    total, ok, count = 0.0, 0, 0
    for g in groups:
        n = g.a_hat.shape[1]
        A = pyrtklib.Arr1Ddouble
        ab, Qb, F, s = A(n), A(n * n), A(2 * n), A(2)
        for k in range(0, len(g.a_hat), stride):
            for i, v in enumerate(g.a_hat[k].tolist()):
                ab[i] = v
            for i, v in enumerate(g.Qa[k].T.ravel().tolist()):
                Qb[i] = v
            os.dup2(devnull, 2)
            try:
                t = time.perf_counter()
                info = rtk(n, 2, ab, Qb, F, s)
                total += time.perf_counter() - t
            finally:
                os.dup2(saved, 2)
            ok += info == 0
            count += 1
    return total, ok / max(count, 1), count


def main(path=None):
    if path is None:
        path = os.path.join(tempfile.mkdtemp(), "xian24h.h5")
        t = time.perf_counter()
        simkit.run("xian_static_bds", out=path, overrides=["imu.preset=ideal"])
        print(f"simulated 24 h xian_static_bds in {time.perf_counter() - t:.1f} s")
    with simkit.open(path) as ds:
        SOLVERS["attitude"](ds, {"stop_s": 30.0}, False)  # compile / load the numba kernels first
        t = time.perf_counter()
        sol = SOLVERS["attitude"](ds, {}, True)
        full = time.perf_counter() - t
        fd = read(ds, merge(AMBIGUITY_DEFAULTS, {}, "attitude"))
    st = sol.extras["status"]
    print(f"attitude (LAMBDA): {len(sol.t)} epochs, {len(np.unique(fd.lever_arm, axis=0))} antennas, "
          f"fixed {np.mean(st == 1):.4f}, wrong fixes {int(np.sum(st == 3))}: {full:.1f} s for the whole solve")
    groups = float_solution(fd.obs, np.radians(10.0))
    t = time.perf_counter()
    for g in groups:
        amb.ils_batch(g.a_hat, g.Qa, n_cands=2)
    ours = time.perf_counter() - t
    stride = 10
    theirs, solved, count = _rtklib_seconds(groups, stride)
    theirs *= sum(len(g.a_hat) for g in groups) / count
    print(f"ambiguity step on the same {sum(len(g.a_hat) for g in groups)} float problems: simkit ils_batch "
          f"{ours:.2f} s, RTKLIB lambda {theirs:.2f} s (from every {stride}th epoch, {solved:.3f} solved): "
          f"simkit / RTKLIB = {ours / theirs:.2f}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
