"""100 ``simkit.ambiguity.ils`` calls at n = 40 in a new process with a warm numba cache, against the same 100
calls once compiled in that process. A first child fills an empty ``NUMBA_CACHE_DIR``; the timed child then
reports the first call (the cache load), calls 2-100, the same 100 calls again compiled, and whether the compiled
kernel was in use right after the first call. Problems: ``studies.ambiguity_problems.random_problem(rng, 40,
"well")``, seed 5. Run: python benchmarks/bench_ils_warm.py [TREE] (default: this checkout).
"""
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import json, sys, time
sys.path.insert(0, sys.argv[1]); sys.path.append(sys.argv[2])
import numpy as np
from simkit.ambiguity import ils, search
from simkit.ambiguity.warmup import wait_for_jit
from studies.ambiguity_problems import random_problem
rng = np.random.default_rng(5)
probs = [random_problem(rng, 40, "well")[:2] for _ in range(100)]
t = []
for a, Q in probs:
    s = time.perf_counter(); ils(a, Q); t.append(time.perf_counter() - s)
    if len(t) == 1:
        at_first = search._ILS.call is search._ils_kernel
wait_for_jit()
s = time.perf_counter()
for a, Q in probs:
    ils(a, Q)
print(json.dumps({"first_s": t[0], "calls_2_100_s": sum(t[1:]), "compiled_100_s": time.perf_counter() - s,
                  "compiled_after_first_call": at_first}))
"""


def main():
    tree = str(Path(sys.argv[1]).resolve()) if len(sys.argv) > 1 else str(ROOT)
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        run = lambda: subprocess.run([sys.executable, "-c", CHILD, tree, str(ROOT)], env=env,  # noqa: E731
                                     capture_output=True, text=True, check=True).stdout.strip().splitlines()[-1]
        run()  # fills the cache
        got = json.loads(run())
    print(json.dumps({"tree": tree, **got, "load_average": os.getloadavg()[0]}))


if __name__ == "__main__":
    main()
