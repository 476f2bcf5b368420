"""Benchmark: truth generation for 1 h at 1 kHz, with and without the compressed HDF5 write (targets >= 1,000,000
samples/s with the write, peak RSS < 1 GiB), against gnss-ins-sim's trajectory generator in the same run.

The peer is gnss-ins-sim (github.com/Aceinna/gnss-ins-sim, not on PyPI), imported from a checkout
(``--peer``, or the ``GNSS_INS_SIM`` environment variable). Its ``pathgen.path_gen`` makes the
true position, velocity, attitude, body rate and specific force from motion commands, one Python step per sample,
so it runs on a shorter record of turns, 200 deg/s rolls and a climbing acceleration at the same rate
(``--peer-seconds``); samples per second is the figure compared. Without the peer only our figures are printed.
Run: python benchmarks/bench_truth.py [--seconds 3600] [--rate 1000] [--peer-seconds 40]
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import psutil

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # this checkout first

import peers  # noqa: E402  (benchmarks/peers.py)
from simkit import run  # noqa: E402
from simkit.scenario.loader import load  # noqa: E402
from simkit.trajectory import Trajectory  # noqa: E402

HIGH_DYNAMIC = ROOT / "scenarios" / "high_dynamic.toml"


def truth_only_scenario(seconds: float, rate: float) -> dict:
    data = load(HIGH_DYNAMIC).data
    return {"scenario": dict(data["scenario"], duration_s=seconds),
            "trajectory": dict(data["trajectory"], rate_hz=rate)}  # truth only: no IMU / GNSS sections


def peak_rss() -> int:
    peak = psutil.Process().memory_info().rss
    try:
        import resource

        peak = max(peak, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)
    except ImportError:
        pass
    return peak


def ours(seconds: float, rate: float) -> tuple[float, float, int]:
    """(samples/s with the HDF5 write, samples/s generation alone, file size in bytes)."""
    data = truth_only_scenario(seconds, rate)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "truth.h5"
        t0 = time.perf_counter()
        run(data, out=out)
        with_write = time.perf_counter() - t0
        size = out.stat().st_size
    sc = load(data)
    traj = Trajectory(sc.trajectory, sc.duration_s)
    t0 = time.perf_counter()
    n = sum(len(block) for block in traj.blocks())
    alone = time.perf_counter() - t0
    return n / with_write, n / alone, size


def gnss_ins_sim_rate(pathgen, seconds: float, rate: float) -> float:
    """gnss-ins-sim's path_gen (NED, 1x over-sampling, no GPS / odometer): samples/s on turns, rolls, a climb."""
    d2r = math.pi / 180.0
    initial = np.array([40.0 * d2r, 116.0 * d2r, 4000.0, 200.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    # type 1 rows: [type, yaw rate, pitch rate, roll rate (deg/s), body accel x, y, z (m/s^2), duration s, gps]
    cycle = [[1, 0, 0, 0, 0, 0, 0, 2.0, 0], [1, 30, 0, 0, 0, 0, 0, 6.0, 0],
             [1, 0, 0, 200, 0, 0, 0, 1.8, 0], [1, 0, 5, 0, 1, 0, 0, 3.0, 0]]
    repeats = max(1, round(seconds / sum(row[7] for row in cycle)))
    motion = np.array(cycle * repeats, dtype=float)
    output = np.array([[1.0, rate], [-1.0, rate], [-1.0, rate]])
    mobility = np.array([10.0, 10.0, 10.0])   # m/s^2, rad/s^2, rad/s: let the commands through unclipped
    t0 = time.perf_counter()
    result = pathgen.path_gen(initial, motion, output, mobility, ref_frame=0)
    elapsed = time.perf_counter() - t0
    if not result["status"]:
        raise RuntimeError("gnss-ins-sim path_gen reported failure")
    return result["nav"].shape[0] / elapsed


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=3600.0)
    ap.add_argument("--rate", type=float, default=1000.0)
    ap.add_argument("--peer-seconds", type=float, default=40.0)
    ap.add_argument("--peer", help="gnss-ins-sim checkout (default: $GNSS_INS_SIM)")
    args = ap.parse_args(argv)
    with_write, alone, size = ours(args.seconds, args.rate)
    peak = peak_rss()
    n = int(args.seconds * args.rate) + 1
    print(f"simkit truth + HDF5 write, high_dynamic {args.seconds:g} s at {args.rate:g} Hz ({n} samples): "
          f"{with_write:,.0f} samples/s (file {size / 1e6:.0f} MB, peak RSS {peak / 2**20:.0f} MiB)")
    print(f"simkit truth generation alone: {alone:,.0f} samples/s")
    print(f"target >= 1,000,000 samples/s with the write: {'met' if with_write >= 1e6 else 'NOT met'}; "
          f"peak RSS < 1 GiB: {'met' if peak < 2**30 else 'NOT met'}")
    pathgen = peers.gnss_ins_sim(args.peer)
    if pathgen is None:
        print("gnss-ins-sim not found (looked in: " + ", ".join(str(p) for p in peers.CANDIDATES)
              + "): no peer figure")
        return 0
    theirs = gnss_ins_sim_rate(pathgen, args.peer_seconds, args.rate)
    print(f"gnss-ins-sim pathgen.path_gen, {args.peer_seconds:g} s at {args.rate:g} Hz: "
          f"{theirs:,.0f} samples/s (truth only, in memory)")
    print(f"ratio simkit / gnss-ins-sim: {alone / theirs:.0f}x generation alone, {with_write / theirs:.0f}x "
          f"with our HDF5 write")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
