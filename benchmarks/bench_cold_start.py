"""Cold and warm start of simkit.ambiguity.ils and of `simkit run quickstart`, each in a fresh subprocess.

Run: python benchmarks/bench_cold_start.py [--repeat N] [--prepared]. "cold" = an empty NUMBA_CACHE_DIR and no
prepared cache (what numba compiles); with --prepared the empty directory is seeded from simkit/_jit as after
`pip install .` (docs/cold_start.md); "warm" = the same directory once a process has cached the kernels. Columns:
- import: `from simkit.ambiguity import ils`;
- first ils: the first call (n = 10, a GNSS-like problem); cold, it runs the kernel interpreted while numba
  compiles in the background (simkit/ambiguity/warmup.py);
- compiled after: from the first call until the compiled kernel is in use (compilation, or the cache load);
- quickstart: `python -m simkit run quickstart -o <tmp>` (other stages compile their own kernels);
- solve: `python -m simkit solve <that file>` (spp and kf15: the Kalman filter loop's compile);
  wall and CPU (user + sys of the child, the figure to compare on a loaded machine) for both. Medians over
  --repeat runs; the load average is printed with the table.
"""
import argparse
import resource
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import json, time
t0 = time.perf_counter()
import numpy as np
from simkit.ambiguity import ils
from studies.ambiguity_problems import random_problem
from simkit.ambiguity.warmup import wait_for_jit
t1 = time.perf_counter()
a, Q, _ = random_problem(np.random.default_rng(1), 10, "well")
t2 = time.perf_counter()
ils(a, Q)
t3 = time.perf_counter()
wait_for_jit()
t4 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "first_ils": t3 - t2, "compiled_after": t4 - t2}))
"""


PREPARED = False  # --prepared: "cold" starts from the install's prepared cache (simkit/_jit, `simkit compile`)


def _env(cache_dir):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache_dir))
    if not PREPARED:
        env["SIMKIT_NO_PREPARED_CACHE"] = "1"  # a real compile, whatever this checkout's simkit/_jit holds
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])
    return env


def first_ils(cache_dir):
    """{import, first_ils, compiled_after} in seconds, from a fresh interpreter."""
    out = subprocess.run([sys.executable, "-c", CHILD], env=_env(cache_dir), capture_output=True, text=True,
                         check=True, timeout=600)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _timed(args, cache_dir):
    """(wall s, CPU s) of ``python -m simkit ARGS`` in a fresh interpreter (CPU: the child's user + sys)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run([sys.executable, "-m", "simkit", *args], env=_env(cache_dir), capture_output=True, check=True,
                   timeout=1200)
    wall, after = time.perf_counter() - t, resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def quickstart(cache_dir):
    """{quickstart, quickstart_cpu, solve, solve_cpu} (s): `simkit run quickstart`, then `simkit solve` on its
    file, each in a fresh interpreter."""
    with tempfile.TemporaryDirectory() as tmp:
        h5 = str(Path(tmp) / "q.h5")
        run = _timed(["run", "quickstart", "-o", h5], cache_dir)
        solve = _timed(["solve", h5], cache_dir)
    return {"quickstart": run[0], "quickstart_cpu": run[1], "solve": solve[0], "solve_cpu": solve[1]}


def _median(xs):
    xs = sorted(xs)
    return xs[len(xs) // 2]


def measure(repeat=3):
    """Rows {state, import, first_ils, compiled_after, quickstart}: medians over ``repeat`` fresh processes."""
    rows = {"cold": [], "warm": []}
    for _ in range(repeat):
        cache = Path(tempfile.mkdtemp(prefix="simkit-numba-"))
        try:
            cold = first_ils(cache)  # empty cache; the child waits for the compilation, which fills it
            warm = first_ils(cache)
            shutil.rmtree(cache)
            cache.mkdir()
            cold.update(quickstart(cache))
            warm.update(quickstart(cache))
        finally:
            shutil.rmtree(cache, ignore_errors=True)
        rows["cold"].append(cold)
        rows["warm"].append(warm)
    return [{"state": s, **{k: _median([r[k] for r in rs]) for k in rs[0]}} for s, rs in rows.items()]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--prepared", action="store_true",
                    help="let the empty cache be seeded from simkit/_jit (run `python -m simkit compile` first)")
    args = ap.parse_args()
    global PREPARED
    PREPARED = args.prepared
    rows = measure(args.repeat)
    print(f"{'numba cache':<12} {'import s':>9} {'first ils s':>12} {'compiled after s':>17} {'quickstart s':>13} "
          f"{'(CPU s)':>8} {'solve s':>8} {'(CPU s)':>8}")
    for r in rows:
        print(f"{r['state']:<12} {r['import']:>9.2f} {r['first_ils']:>12.3f} {r['compiled_after']:>17.2f} "
              f"{r['quickstart']:>13.1f} {r['quickstart_cpu']:>8.1f} {r['solve']:>8.1f} {r['solve_cpu']:>8.1f}")
    print(f"load average (1 min) at the end: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
