"""Where the wall time of a truth + IMU run goes: a timeline of its lanes (issue 25).

Runs ``python -m simkit run`` of :func:`bench_truth_imu.scenario` in a fresh interpreter with its stages wrapped
(the truth blocks on their worker thread, the IMU and the writer's calls on the main thread, each compression job
on the thread that ran it: a pool thread, a lane worker or the main thread while it waits, the file's close) and prints, for each lane, its busy spans and CPU, then a strip chart in bins
of wall time from the process start, the idle gaps and the serial head (before the first truth block ends) and tail
(after the last IMU block ends).

    python benchmarks/timeline_truth_imu.py [--seconds 600] [--rate 1000] [--bins 40] [--json OUT] [--tree DIR]

``--tree``: the checkout to run (default this one; the code before issue 25's third round works too).
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_truth_imu  # noqa: E402

# Runs in the child: time.perf_counter is CLOCK_MONOTONIC on Linux, so its readings compare with the parent's.
PROBE = r"""
import atexit, sys, threading, time
T_MAIN = time.perf_counter()
spans = []                                    # (lane, label, start, end, thread CPU s)


def timed(lane, label, fn):
    def run(*args, **kwargs):
        w, c = time.perf_counter(), time.thread_time()
        try:
            return fn(*args, **kwargs)
        finally:
            name = lane if lane != "pool" else "compress@" + threading.current_thread().name
            spans.append((name, label, w, time.perf_counter(), time.thread_time() - c))
    return run


import simkit.cli
if hasattr(simkit.cli, "one_blas_thread"):   # as `simkit run` does, before numpy loads (absent in older trees)
    simkit.cli.one_blas_thread()
from simkit import pipeline
from simkit.imu import simulator
from simkit.io import writer
from simkit.trajectory import generator
T_IMPORTED = time.perf_counter()
generator.Trajectory._integrate = timed("truth", "truth block", generator.Trajectory._integrate)
simulator.ImuSimulator.process = timed("main", "imu", simulator.ImuSimulator.process)
writer.Writer.append = timed("main", "append", writer.Writer.append)
writer.Writer.__enter__ = timed("main", "open", writer.Writer.__enter__)
writer.Writer.__exit__ = timed("main", "close", writer.Writer.__exit__)
if hasattr(writer, "shuffle_deflate"):
    writer.shuffle_deflate = timed("pool", "deflate", writer.shuffle_deflate)
else:  # the code before issue 25's third round
    writer._shuffle_deflate = timed("pool", "deflate", writer._shuffle_deflate)
writer._first_chunk = timed("pool", "first chunk", writer._first_chunk)
c0 = time.process_time()


@atexit.register  # simkit.cli.console runs the atexit handlers, then ends the process without the teardown
def report():
    import json, resource
    ru = resource.getrusage(resource.RUSAGE_SELF)
    print(json.dumps({"main": T_MAIN, "imported": T_IMPORTED, "end": T_END, "cpu": ru.ru_utime + ru.ru_stime,
                      "cpu_before_run": c0, "spans": spans}))


def main(argv):
    global T_END
    try:
        return real_main(argv)
    finally:
        T_END = time.perf_counter()


T_END, real_main, simkit.cli.main = None, simkit.cli.main, main
sys.exit(simkit.cli.console(sys.argv[1:]) if hasattr(simkit.cli, "console") else main(sys.argv[1:]))
"""


def measure(seconds: float, rate: float, tree: Path = ROOT) -> dict:
    """One instrumented run of ``tree``: the child's spans with times in seconds from the parent's spawn."""
    with tempfile.TemporaryDirectory(prefix="timeline_truth_imu_") as tmp:
        path = Path(tmp) / "s.toml"
        path.write_text(bench_truth_imu.scenario(seconds, rate))
        t0 = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", PROBE, "run", str(path), "-o", str(Path(tmp) / "o.h5"), "-q"],
                             cwd=tree, capture_output=True, text=True)
        t_exit = time.perf_counter() - t0
    if out.returncode != 0:
        raise RuntimeError(out.stderr[-2000:])
    r = json.loads(out.stdout.splitlines()[-1])
    r["spans"] = [(lane, label, a - t0, b - t0, cpu) for lane, label, a, b, cpu in r["spans"]]
    for k in ("main", "imported", "end"):
        r[k] -= t0
    r["exit"] = t_exit
    return r


def report(r: dict, bins: int) -> None:
    spans = r["spans"]
    lanes = sorted({s[0] for s in spans}, key=lambda n: (n != "truth", n != "main", n))
    print(f"process: interpreter ready {r['main']:.3f} s, imports done {r['imported']:.3f} s, run returned "
          f"{r['end']:.3f} s, exit seen {r['exit']:.3f} s; CPU {r['cpu']:.2f} s ({r['cpu_before_run']:.2f} s before "
          f"the run)")
    for lane in lanes:
        mine = [s for s in spans if s[0] == lane]
        by_label: dict[str, list] = {}
        for s in mine:
            by_label.setdefault(s[1], []).append(s)
        parts = ", ".join(f"{label} x{len(v)} {sum(x[3] - x[2] for x in v):.3f} s wall / "
                          f"{sum(x[4] for x in v):.3f} s CPU" for label, v in by_label.items())
        print(f"  {lane:<28} {min(s[2] for s in mine):.3f}-{max(s[3] for s in mine):.3f} s: {parts}")
    truth = sorted(s for s in spans if s[1] == "truth block")
    imu = sorted((s for s in spans if s[1] == "imu"), key=lambda s: s[2])
    close = [s for s in spans if s[1] == "close"]
    if truth and imu:
        print(f"serial head: imports end {r['imported']:.3f} s -> first truth block starts {truth[0][2]:.3f} s, "
              f"ends {truth[0][3]:.3f} s; tail: last IMU block ends {imu[-1][3]:.3f} s, close "
              f"{close[0][2]:.3f}-{close[0][3]:.3f} s, process exit {r['exit']:.3f} s")
        print("truth blocks (start-end): " + ", ".join(f"{s[2]:.3f}-{s[3]:.3f}" for s in truth))
        print("IMU blocks   (start-end): " + ", ".join(f"{s[2]:.3f}-{s[3]:.3f}" for s in imu))
    width = r["exit"] / bins
    print(f"busy fraction per lane, bins of {width * 1000:.0f} ms from the spawn (# > 2/3, + > 1/3, . > 0):")
    for lane in lanes:
        busy = [0.0] * bins
        for s in (s for s in spans if s[0] == lane and s[1] not in ("append", "close")):
            for i in range(bins):
                lo, hi = i * width, (i + 1) * width
                busy[i] += max(0.0, min(hi, s[3]) - max(lo, s[2]))
        print(f"  {lane[-12:]:>12} |" + "".join("#" if b > 2 * width / 3 else "+" if b > width / 3 else "." if b > 0
                                              else " " for b in busy) + "|")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=600.0)
    ap.add_argument("--rate", type=float, default=1000.0)
    ap.add_argument("--bins", type=int, default=40)
    ap.add_argument("--json", help="also write the spans as JSON to this file")
    ap.add_argument("--tree", type=Path, default=ROOT, help="the checkout to run (default: this one)")
    args = ap.parse_args(argv)
    r = measure(args.seconds, args.rate, args.tree.resolve())
    report(r, args.bins)
    if args.json:
        Path(args.json).write_text(json.dumps(r, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
