"""Where numba's compile time goes: the self CPU time of every function numba compiles during one kf15 call on
2 s of data (``bench_kf.data``), from numba's ``numba:compile`` events (a callee's compile is subtracted from its
caller's), largest first, with the number of specialisations of each. Run it with an empty cache, or it measures
cache loads:

    NUMBA_CACHE_DIR=$(mktemp -d) python benchmarks/profile_compile.py [--top N] [--signatures]

(docs/cold_start.md has the findings.)
"""
from __future__ import annotations

import argparse
import collections
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import numba.core.event as ev  # noqa: E402


class SelfTime(ev.Listener):
    """Self CPU seconds, call count and signatures per compiled function."""

    def __init__(self):
        self.stack, self.seconds = [], collections.Counter()
        self.count, self.sigs = collections.Counter(), collections.defaultdict(set)

    def on_start(self, event):
        self.stack.append([time.process_time(), 0.0])

    def on_end(self, event):
        t0, children = self.stack.pop()
        d = time.process_time() - t0
        fn = event.data["dispatcher"].py_func
        name = f"{fn.__module__}.{fn.__qualname__}"
        self.seconds[name] += d - children
        self.count[name] += 1
        self.sigs[name].add(str(event.data["args"]))
        if self.stack:
            self.stack[-1][1] += d


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--signatures", action="store_true", help="list the signatures of functions compiled twice+")
    a = ap.parse_args()
    rec = SelfTime()
    ev.register("numba:compile", rec)
    from bench_kf import CFG, data
    from simkit.estimators import KalmanFilter15

    imu, gnss, init = data(2.0)
    c = time.process_time()
    KalmanFilter15(CFG, init).run(imu, gnss)
    print(f"kf15 first call: {time.process_time() - c:.1f} s of CPU")
    for name, s in rec.seconds.most_common(a.top):
        print(f"{s:7.2f} s {rec.count[name]:3d}x {name}")
    if a.signatures:
        for name, sigs in rec.sigs.items():
            if len(sigs) > 1:
                print(name, *sorted(sigs), sep="\n    ")


if __name__ == "__main__":
    main()
