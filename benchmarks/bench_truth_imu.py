"""Benchmark: truth + IMU, 600 s at 1 kHz, end to end (interpreter start-up, imports, generation, file write), against
gnss-ins-sim doing the same job in the same run.

Ours: ``python -m simkit run`` on the high_dynamic flight (5-7 g turns, 200+ deg/s rolls, a loop) at 1 kHz with the
STIM300 IMU (turn-on bias, flicker bias instability, ARW/VRW, scale factor, misalignment, g-sensitivity, 262 Hz
bandwidth, range), no GNSS, into one HDF5 file: truth (8 datasets), IMU (gyro, accel) and every error term.
The peer (github.com/Aceinna/gnss-ins-sim, not on PyPI; a checkout from ``--peer`` or ``$GNSS_INS_SIM``) in a fresh
interpreter: ``ins_sim.Sim`` on a motion profile of turns, 200 deg/s rolls and a climbing acceleration at the same
rate, with the STIM300's bias, ARW/VRW and bias instability (first-order Gauss-Markov, its model), ``run()`` and
``results(dir)``, its own output (CSV files). Both are timed as child processes: wall time and CPU time
(user + system of the child, so threads count), in interleaved rounds (simkit's median of 5 runs, then one peer
run; 3 rounds): the ratio is the median of the rounds' ratios, each round's printed beside it. Also printed: the
peer's generation alone in memory (``path_gen`` + ``gyro_gen`` + ``acc_gen``, no start-up, no file), the strictest
comparison, and where simkit's CPU goes (one more run, instrumented: start-up, imports, truth, IMU, compression,
writes).

    python benchmarks/bench_truth_imu.py [--seconds 600] [--rate 1000] [--peer DIR] [--rounds 3] [--json OUT]
    python benchmarks/bench_truth_imu.py --ab OLD_TREE NEW_TREE [--rounds 3]     (before / after, no peer)
    python benchmarks/bench_truth_imu.py --stages [--tree DIR]    (the truth and the IMU alone, one thread, no file)
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))

import peers  # noqa: E402  (benchmarks/peers.py)
import timing  # noqa: E402

# gnss-ins-sim: turns, 200 deg/s rolls and a climbing acceleration (type 1 rows: yaw, pitch, roll rates in deg/s,
# body accelerations in m/s^2, duration s, GPS visibility), the cycle of bench_truth.py
PEER_CYCLE = [(1, 0, 0, 0, 0, 0, 0, 2.0, 0), (1, 30, 0, 0, 0, 0, 0, 6.0, 0), (1, 0, 0, 200, 0, 0, 0, 1.8, 0),
              (1, 0, 5, 0, 1, 0, 0, 3.0, 0)]
PEER = r"""
import contextlib, io, sys
import numpy as np
sys.path.insert(0, sys.argv[1])
from gnss_ins_sim.sim import imu_model, ins_sim
seconds, rate, out = float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
cycle = %r
rows = cycle * max(1, round(seconds / sum(r[7] for r in cycle)))
motion = "ini lat,ini lon,ini alt,vx,vy,vz,yaw,pitch,roll\n40,116,4000,200,0,0,0,0,0\n" \
         "type,yaw,pitch,roll,vx,vy,vz,t,gps\n" + "\n".join(",".join(str(v) for v in r) for r in rows)
g = 9.80665
stim300 = {"gyro_b": np.full(3, 250.0), "gyro_arw": np.full(3, 0.15), "gyro_b_stability": np.full(3, 0.3),
           "gyro_b_corr": np.full(3, 100.0), "accel_b": np.full(3, 0.75e-3 * g), "accel_vrw": np.full(3, 0.06),
           "accel_b_stability": np.full(3, 0.05e-3 * g), "accel_b_corr": np.full(3, 100.0)}
imu = imu_model.IMU(accuracy=stim300, axis=6, gps=False)
sim = ins_sim.Sim([rate, 0.0, 0.0], motion, ref_frame=0, imu=imu, mode=np.array([100.0, 5000.0, 500.0]))
with contextlib.redirect_stdout(io.StringIO()):
    sim.run(1)
    sim.results(out)
print(sim.dmgr.time.data.size)
""" % (PEER_CYCLE,)


def child(cmd: list[str], cwd: Path | None = None) -> tuple[float, float, str]:
    """(wall s, CPU s of the child and its threads, stdout) of one command."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd[:4])} ...: exit {out.returncode}\n{out.stderr[-2000:]}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, out.stdout


def scenario(seconds: float, rate: float) -> str:
    """high_dynamic without GNSS, at ``rate`` Hz for ``seconds``, with the STIM300 IMU (TOML text)."""
    import tomli_w

    data = tomllib.loads((ROOT / "scenarios" / "high_dynamic.toml").read_text())
    data.pop("gnss")
    data["scenario"]["duration_s"] = seconds
    data["trajectory"]["rate_hz"] = rate
    data["imu"] = {"preset": "stim300"}
    return tomli_w.dumps(data)


OUR_RUNS = 5  # simkit's figure is the median of this many fresh runs (a run is under a second: one is noisy)


def ours(tmp: Path, seconds: float, rate: float, runs: int = OUR_RUNS) -> tuple[float, float, int]:
    """(wall s, CPU s, file bytes) of ``python -m simkit run`` in a fresh interpreter (this checkout): the median
    wall and CPU of ``runs`` runs."""
    path = tmp / "truth_imu.toml"
    path.write_text(scenario(seconds, rate))
    out = tmp / "truth_imu.h5"
    times = []
    for _ in range(runs):
        out.unlink(missing_ok=True)
        times.append(child([sys.executable, "-m", "simkit", "run", str(path), "-o", str(out), "-q"], cwd=ROOT)[:2])
    size = out.stat().st_size
    out.unlink()  # not written back to disk while the peer runs
    os.sync()
    return statistics.median(w for w, _ in times), statistics.median(c for _, c in times), size


def theirs(tmp: Path, checkout: Path, seconds: float, rate: float) -> tuple[float, float, int, int]:
    """(wall s, CPU s, bytes written, samples) of gnss-ins-sim's Sim.run + results in a fresh interpreter."""
    out = tmp / "peer"
    out.mkdir()
    wall, cpu, stdout = child([sys.executable, "-c", PEER, str(checkout), str(seconds), str(rate), str(out)])
    size = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())
    shutil.rmtree(out)  # its ~400 MB would otherwise be written back to disk during the next round's runs
    os.sync()
    return wall, cpu, size, int(stdout.split()[-1])


def theirs_in_memory(pathgen, seconds: float, rate: float) -> float:
    """Samples/s of path_gen + gyro_gen + acc_gen in this process (no start-up, no file): CPU time."""
    import numpy as np

    d2r = np.pi / 180.0
    initial = np.array([40.0 * d2r, 116.0 * d2r, 4000.0, 200.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    rows = PEER_CYCLE * max(1, round(seconds / sum(r[7] for r in PEER_CYCLE)))
    motion = np.array(rows, dtype=float)
    motion[:, 1:4] *= d2r
    gyro_err = {"b": np.full(3, 250.0 / 3600 * d2r), "b_drift": np.full(3, 0.3 / 3600 * d2r),
                "b_corr": np.full(3, 100.0), "arw": np.full(3, 0.15 / 60 * d2r)}
    acc_err = {"b": np.full(3, 7.4e-3), "b_drift": np.full(3, 4.9e-4), "b_corr": np.full(3, 100.0),
               "vrw": np.full(3, 0.06 / 60)}
    c0 = time.process_time()
    res = pathgen.path_gen(initial, motion, np.array([[1.0, rate], [-1.0, rate], [-1.0, rate]]),
                           np.array([100.0, 5000.0 * d2r, 500.0 * d2r]), ref_frame=0)
    pathgen.gyro_gen(rate, res["imu"][:, 4:7], gyro_err)
    pathgen.acc_gen(rate, res["imu"][:, 1:4], acc_err)
    return res["nav"].shape[0] / (time.process_time() - c0)


BREAKDOWN = r"""
import json, resource, sys, threading, time
t_python = time.process_time()                      # the interpreter's own start-up (site, encodings)
import simkit.cli
simkit.cli.one_blas_thread()                        # as `simkit run` does, before numpy loads
from simkit.heap import keep_freed_memory
from simkit import pipeline
from simkit.imu import simulator
from simkit.io import writer
from simkit.trajectory import generator
t_imports = time.process_time() - t_python
keep_freed_memory()                                 # as `simkit run` does
lanes = {"truth": 0.0, "imu": 0.0, "compression": 0.0, "compression_main": 0.0}
lock = threading.Lock()


def timed(name, fn):
    def run(*args, **kwargs):
        c = time.thread_time()
        try:
            return fn(*args, **kwargs)
        finally:
            spent = time.thread_time() - c
            with lock:
                lanes[name] += spent
                if name == "compression" and threading.current_thread() is threading.main_thread():
                    lanes["compression_main"] += spent
    return run


generator.Trajectory._integrate = timed("truth", generator.Trajectory._integrate)
simulator.ImuSimulator.process = timed("imu", simulator.ImuSimulator.process)
writer._deflated = timed("compression", writer._deflated)  # a first chunk's job calls it too
w0, m0, p0 = time.perf_counter(), time.thread_time(), time.process_time()
pipeline.run(sys.argv[1], sys.argv[2])
main, process = time.thread_time() - m0, time.process_time() - p0
ru = resource.getrusage(resource.RUSAGE_SELF)
print(json.dumps({"python": t_python, "imports": t_imports, "run_wall": time.perf_counter() - w0, "run_cpu": process,
                  "truth": lanes["truth"], "imu": lanes["imu"], "compression": lanes["compression"],
                  "compression_main": lanes["compression_main"],
                  "rest_main": main - lanes["imu"] - lanes["compression_main"],
                  "rest_workers": process - main - lanes["truth"] - (lanes["compression"] - lanes["compression_main"]),
                  "user": ru.ru_utime, "system": ru.ru_stime, "minor_faults": ru.ru_minflt}))
"""


def breakdown(tmp: Path, seconds: float, rate: float) -> dict:
    """Where one run's CPU goes, in a fresh interpreter (this checkout): the interpreter's start-up, the imports,
    the truth (on the lane's worker), the IMU, the compression (on either thread) and the rest of each thread (the
    HDF5 writes on the main thread); thread CPU times, user and system time, page faults."""
    path = tmp / "breakdown.toml"
    path.write_text(scenario(seconds, rate))
    _, _, stdout = child([sys.executable, "-c", BREAKDOWN, str(path), str(tmp / "breakdown.h5")], cwd=ROOT)
    return json.loads(stdout.splitlines()[-1])


AB_PROBE = r"""
import resource, subprocess, sys, time
tree, scenario = sys.argv[1], sys.argv[2]
t0 = time.perf_counter()
subprocess.run([sys.executable, "-m", "simkit", "run", scenario, "-o", scenario + ".h5", "-q"], cwd=tree, check=True)
r = resource.getrusage(resource.RUSAGE_CHILDREN)
print(f"{time.perf_counter() - t0:.2f} {r.ru_utime + r.ru_stime:.2f}")
"""


STAGES = r"""
import sys, time
import simkit.cli
if hasattr(simkit.cli, "one_blas_thread"):    # as `simkit run` does (absent in older trees)
    simkit.cli.one_blas_thread()
from simkit.heap import keep_freed_memory
keep_freed_memory()                            # as simkit.pipeline.run does: without it every block faults its pages
from simkit import pipeline
from simkit.scenario import load
sc = load(sys.argv[1], [])
truth_cpu = imu_cpu = float("inf")
for _ in range(3):
    stages, t_truth, t_imu = pipeline.build(sc), 0.0, 0.0
    blocks = stages.trajectory.blocks(block_samples=pipeline.BLOCK_SAMPLES)
    while True:
        c = time.thread_time()
        truth = next(blocks, None)
        t_truth += time.thread_time() - c
        if truth is None:
            break
        c = time.thread_time()
        stages.imu.process(truth.t, truth.omega_ib_b, truth.f_ib_b)
        t_imu += time.thread_time() - c
    truth_cpu, imu_cpu = min(truth_cpu, t_truth), min(imu_cpu, t_imu)
print(f"truth {truth_cpu:.3f} s CPU, IMU {imu_cpu:.3f} s CPU (one thread, no file, best of 3)")
"""


def stages(tree: Path, seconds: float, rate: float) -> None:
    """The truth and the IMU of the scenario alone in ``tree``'s code, on one thread (thread CPU, best of 3)."""
    with tempfile.TemporaryDirectory(prefix="bench_truth_imu_stages_") as tmp:
        path = Path(tmp) / "truth_imu.toml"
        path.write_text(scenario(seconds, rate))
        print(child([sys.executable, "-c", STAGES, str(path)], cwd=tree)[2].strip())


def ab(trees, seconds: float, rate: float, rounds: int) -> None:
    """``python -m simkit run`` of the same scenario in each tree, alternating (timing.ab): wall and CPU s."""
    with tempfile.TemporaryDirectory(prefix="bench_truth_imu_ab_") as tmp:
        path = Path(tmp) / "truth_imu.toml"
        path.write_text(scenario(seconds, rate))
        timing.ab(trees, AB_PROBE, ["wall s", "CPU s"], rounds, path, own_cache=True)


ROUNDS = 3  # rounds of (OUR_RUNS simkit runs, one peer run) when the peer is there: see measure()


def measure(seconds: float = 600.0, rate: float = 1000.0, peer: str | None = None, rounds: int = ROUNDS) -> dict:
    """Every figure of this benchmark, measured in this run (the peer's are None without a checkout).

    With the peer, ``rounds`` rounds of (simkit's median of :data:`OUR_RUNS` runs, one peer run), interleaved: this
    machine's speed drifts by ~10 % within minutes, so each ratio is taken between runs less than a minute apart,
    and the figures are the medians over the rounds (the ratio: the median of the rounds' ratios), with every
    round's figures kept in ``rounds``."""
    n = int(round(seconds * rate)) + 1
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="bench_truth_imu_") as tmp:
        tmp = Path(tmp)
        # byte-compiled as pip installs it (PYTHONDONTWRITEBYTECODE would otherwise compile every module in every
        # run: ~0.05 s), then the page cache warmed (not numba: a truth + IMU run does not import it)
        child([sys.executable, "-m", "compileall", "-q", str(ROOT / "simkit")], cwd=ROOT)
        child([sys.executable, "-m", "simkit", "run", "--help"], cwd=ROOT)
        pathgen = peers.gnss_ins_sim(peer)
        checkout = Path(pathgen.__file__).resolve().parents[2] if pathgen is not None else None
        per_round = []
        for k in range(rounds if checkout is not None else 1):
            wall, cpu, size = ours(tmp, seconds, rate)
            one = {"ours": {"wall_s": wall, "cpu_s": cpu, "bytes": size}, "peer": None}
            if checkout is not None:
                pw, pc, psize, pn = theirs(tmp, checkout, seconds, rate)
                one["peer"] = {"wall_s": pw, "cpu_s": pc, "bytes": psize, "samples": pn}
            per_round.append(one)
        result = {"samples": n, "seconds": seconds, "rate_hz": rate, "load_before": load, "rounds": per_round,
                  "ours": _median([r["ours"] for r in per_round]), "peer": None, "peer_in_memory_samples_per_s": None}
        result["breakdown"] = breakdown(tmp, seconds, rate)
        if checkout is not None:
            result["peer"] = _median([r["peer"] for r in per_round])
            result["peer_in_memory_samples_per_s"] = theirs_in_memory(pathgen, min(seconds, 60.0), rate)
    result["load_after"] = os.getloadavg()[0]
    return result


def _median(figures: list[dict]) -> dict:
    """Each figure's median over the rounds."""
    return {key: statistics.median(f[key] for f in figures) for key in figures[0]}


def report(r: dict) -> list[tuple[str, str, str, str]]:
    """(figure, ours, peer, ratio) rows: the medians over the rounds, and each round's ratio."""
    n = r["samples"]
    o, p = r["ours"], r["peer"]
    rounds = len(r["rounds"])
    rows = [(f"truth + IMU, {r['seconds']:g} s at {r['rate_hz'] / 1000:g} kHz, start-up + write, wall (simkit: median "
             f"of {OUR_RUNS} runs" + (f"; median of {rounds} interleaved rounds" if p is not None else "") + ")",
             f"{o['wall_s']:.2f} s ({n / o['wall_s']:,.0f} samples/s)"),
            ("truth + IMU, CPU (user + system)", f"{o['cpu_s']:.2f} s")]
    out = []
    for (name, ours_text), key in zip(rows, ("wall_s", "cpu_s")):
        if p is None:
            out.append((name, ours_text, "peer absent", "-"))
            continue
        ratios = [(n / one["ours"][key]) / (one["peer"]["samples"] / one["peer"][key]) for one in r["rounds"]]
        spread = f" (rounds {', '.join(f'{x:.1f}' for x in ratios)})" if rounds > 1 else ""
        out.append((name, ours_text, f"{p[key]:.1f} s ({p['samples'] / p[key]:,.0f} samples/s)",
                    f"{statistics.median(ratios):.1f}x{spread}"))
    if r["peer_in_memory_samples_per_s"]:
        peer_rate = r["peer_in_memory_samples_per_s"]
        out.append(("same, against the peer's generation alone (in memory, no start-up, no file; CPU)",
                    f"{n / o['cpu_s']:,.0f} samples/s", f"{peer_rate:,.0f} samples/s",
                    f"{n / o['cpu_s'] / peer_rate:.1f}x"))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=600.0)
    ap.add_argument("--rate", type=float, default=1000.0)
    ap.add_argument("--peer", help="gnss-ins-sim checkout (default: $GNSS_INS_SIM)")
    ap.add_argument("--json", help="also write the figures as JSON to this file")
    ap.add_argument("--ab", nargs=2, metavar=("A", "B"), help="time two checkouts against each other instead")
    ap.add_argument("--rounds", type=int, default=ROUNDS,
                    help="interleaved (simkit, peer) rounds; with --ab, alternations of the two trees")
    ap.add_argument("--stages", action="store_true", help="time the truth and the IMU alone instead")
    ap.add_argument("--tree", type=Path, default=ROOT, help="with --stages: the checkout to time (default: this one)")
    args = ap.parse_args(argv)
    if args.stages:
        stages(args.tree.resolve(), args.seconds, args.rate)
        return 0
    if args.ab:
        ab(args.ab, args.seconds, args.rate, args.rounds)
        return 0
    r = measure(args.seconds, args.rate, args.peer, args.rounds)
    print(f"{r['samples']:,} samples ({args.seconds:g} s at {args.rate:g} Hz), load average "
          f"{r['load_before']:.2f} before, {r['load_after']:.2f} after; simkit file {r['ours']['bytes'] / 1e6:.0f} MB"
          + (f", gnss-ins-sim CSV {r['peer']['bytes'] / 1e6:.0f} MB" if r["peer"] else
             "; gnss-ins-sim not found (--peer DIR or GNSS_INS_SIM=DIR): no peer figure"))
    timing.print_table(["figure", "simkit", "gnss-ins-sim", "ratio"], report(r))
    b = r["breakdown"]
    print(f"simkit's CPU, one more run in the same session (thread CPU s): interpreter {b['python']:.2f}, imports "
          f"{b['imports']:.2f}, truth (lane worker) {b['truth']:.2f}, IMU {b['imu']:.2f}, compression "
          f"{b['compression']:.2f} (of which {b['compression_main']:.2f} on the main thread while it waited), writes "
          f"and the rest on the main thread {b['rest_main']:.2f}, on the worker {b['rest_workers']:.2f}; run wall "
          f"{b['run_wall']:.2f} s; process user {b['user']:.2f} + system {b['system']:.2f} s, "
          f"{b['minor_faults']:,} page faults")
    if args.json:
        Path(args.json).write_text(json.dumps(r, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
