"""100 ``simkit.ambiguity.ils`` calls at n = 40 in this process, then the same 100 calls once compiled: the child
program of ``benchmarks/bench_ils_warm.py`` and ``tests/test_ambiguity_cold_start.py`` (run it in a fresh process
with a warm or an empty ``NUMBA_CACHE_DIR``). Problems: ``random_problem(rng, 40, "well")``, seed 5.

    PYTHONPATH=TREE python studies/ils_warm.py   -> one JSON line: first_s, calls_2_100_s, compiled_100_s (s, wall) and
                                       compiled_after_first_call (the compiled kernel in use, no compile running)
"""
import json
import time

import numpy as np

from simkit.ambiguity import ils, search
from simkit.ambiguity.warmup import compiling, wait_for_jit
from studies.ambiguity_problems import random_problem


def measure() -> dict:
    rng = np.random.default_rng(5)
    probs = [random_problem(rng, 40, "well")[:2] for _ in range(100)]
    t, at_first = [], False
    for a, q in probs:
        s = time.perf_counter()
        ils(a, q)
        t.append(time.perf_counter() - s)
        if len(t) == 1:
            at_first = search._ILS.call is search._ils_kernel and not compiling()
    wait_for_jit()
    s = time.perf_counter()
    for a, q in probs:
        ils(a, q)
    return {"first_s": t[0], "calls_2_100_s": sum(t[1:]), "compiled_100_s": time.perf_counter() - s,
            "compiled_after_first_call": bool(at_first)}


if __name__ == "__main__":
    print(json.dumps(measure()))
