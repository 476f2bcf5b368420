"""100 ``simkit.ambiguity.ils`` calls at n = 40 in a new process with a warm numba cache, against the same 100
calls once compiled in that process. A first child fills an empty ``NUMBA_CACHE_DIR``; the timed child then
reports the first call (the cache load), calls 2-100, the same 100 calls again compiled, and whether the compiled
kernel was in use right after the first call (the child program is ``studies/ils_warm.py``, which the cold-start
test runs too). Run: python benchmarks/bench_ils_warm.py [TREE] (default: this checkout).
"""
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]



def main():
    tree = str(Path(sys.argv[1]).resolve()) if len(sys.argv) > 1 else str(ROOT)
    with tempfile.TemporaryDirectory() as cache:
        # TREE's simkit first, this checkout's studies package after it
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=os.pathsep.join([tree, str(ROOT)]))
        child = [sys.executable, str(ROOT / "studies" / "ils_warm.py")]
        run = lambda: subprocess.run(child, env=env, capture_output=True, text=True,  # noqa: E731
                                     check=True).stdout.strip().splitlines()[-1]
        run()  # fills the cache
        got = json.loads(run())
    print(json.dumps({"tree": tree, **got, "load_average": os.getloadavg()[0]}))


if __name__ == "__main__":
    main()
