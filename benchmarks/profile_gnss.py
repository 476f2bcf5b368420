"""cProfile of the observables stage of ``bench_gnss.py`` (xian_static_bds, GPS + BDS, 3 antennas, 2 signals),
timed in CPU seconds (``time.process_time``: robust to other load on a shared machine). Both lanes of the stage
(``GnssSimulator.process_blocks``) run on the calling thread here, since cProfile sees one thread.

Run: ``python benchmarks/profile_gnss.py [--hours H] [--top N]``; prints the top functions by cumulative time.
"""
from __future__ import annotations

import argparse
import cProfile
import pstats
import time

from bench_gnss import ours


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=24.0)
    ap.add_argument("--top", type=int, default=25)
    args = ap.parse_args()
    ours(0.05)  # kernels compiled or loaded before the profile
    prof = cProfile.Profile(time.process_time)
    wall, cpu, m, s, n_obs = prof.runcall(ours, args.hours, ahead=False)
    print(f"{args.hours:g} h, {m} epochs, {s} satellites: {wall:.1f} s wall, {cpu:.1f} s CPU (under the profiler)")
    pstats.Stats(prof).strip_dirs().sort_stats("cumulative").print_stats(args.top)


if __name__ == "__main__":
    main()
