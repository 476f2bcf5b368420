"""IMU benchmark: 1 h at 1 kHz, six axes, every error term on, written to HDF5; peers measured in the same run.

Prints our throughput, peak RSS, and the ratio against
  (a) gnss-ins-sim's IMU error generation (``pathgen.gyro_gen`` / ``acc_gen``: constant bias, first-order
      Gauss-Markov bias drift, white noise; fewer terms than ours), from a checkout named by GNSS_INS_SIM (not on PyPI);
  (b) allantools' flicker-noise generator (Kasdin fractional-difference, allantools.noise.pink);
  (c) allantools.oadev against simkit.imu.allan.adev on the same record.
Run: python benchmarks/bench_imu.py [--hours H] [--compression none|lzf|gzip]
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np
import psutil

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing

import peers  # noqa: E402  (benchmarks/peers.py)
from simkit.imu import ImuSimulator, parse_config
from simkit.imu.allan import adev
from simkit.section import Section

ALL_TERMS = {
    "preset": "stim300",   # turn-on bias, flicker, ARW, scale factor, non-linearity, misalignment, g-sens, range, 262 Hz
    "gyro": {"rrw_deg_per_h_per_sqrt_h": 0.05, "quantization_urad": 0.5,
             "gauss_markov": [{"sigma_deg_per_h": 2.0, "tau_s": 30.0}]},
    "accel": {"rrw_ug_per_sqrt_h": 20.0, "quantization_mm_per_s": 0.01,
              "gauss_markov": [{"sigma_ug": 50.0, "tau_s": 60.0}]},
}
RATE = 1000.0
BLOCK = 60_000


def truth_block(t):
    omega = np.stack([0.5 * np.sin(0.7 * t), 0.3 * np.cos(1.3 * t), 0.2 + 0.1 * np.sin(0.2 * t)], axis=1)
    f = np.stack([2.0 * np.sin(0.9 * t), np.cos(0.4 * t), 9.8 + 3.0 * np.sin(0.3 * t)], axis=1)
    return omega, f


def run_ours(n, path, compression, all_errors):
    sim = ImuSimulator(parse_config(Section(ALL_TERMS, "imu")), RATE, 1)
    opts = {"compression": compression} if compression != "none" else {}
    if compression == "gzip":
        opts.update(compression_opts=1, shuffle=True)
    t_truth = t_imu = t_write = 0.0
    with h5py.File(path, "w") as h5:
        dsets = {}
        for start in range(0, n, BLOCK):
            t0 = time.perf_counter()
            t = np.arange(start, min(n, start + BLOCK)) / RATE
            omega, f = truth_block(t)
            t1 = time.perf_counter()
            block = sim.process(t, omega, f)
            gyro, accel, errors = block.gyro, block.accel, block.errors
            t2 = time.perf_counter()
            kept = errors if all_errors else {k: v for k, v in errors.items() if k.endswith("_bias")}
            arrays = {"imu/gyro": gyro, "imu/accel": accel, **{f"imu/errors/{k}": v for k, v in kept.items()}}
            for name, arr in arrays.items():
                if name not in dsets:
                    dsets[name] = h5.create_dataset(name, shape=(n, 3), dtype="f8", chunks=(min(n, BLOCK // 4), 3), **opts)
                dsets[name][start:start + arr.shape[0]] = arr
            t3 = time.perf_counter()
            t_truth, t_imu, t_write = t_truth + t1 - t0, t_imu + t2 - t1, t_write + t3 - t2
        n_sets = len(dsets)
    return t_imu, t_write, t_truth, n_sets


def gnss_ins_sim_rate(pathgen, n: int) -> float:
    """Axis-samples/s of gnss-ins-sim's gyro_gen + acc_gen on n samples of the same truth (bias, Gauss-Markov
    drift of 30 s / 60 s as in ALL_TERMS, white noise)."""
    omega, f = truth_block(np.arange(n) / RATE)
    gyro_err = {"b": np.full(3, 1e-5), "b_drift": np.full(3, 1e-5), "b_corr": np.full(3, 30.0),
                "arw": np.full(3, 1e-4)}
    acc_err = {"b": np.full(3, 1e-3), "b_drift": np.full(3, 5e-4), "b_corr": np.full(3, 60.0),
               "vrw": np.full(3, 1e-3)}
    t0 = time.perf_counter()
    pathgen.gyro_gen(RATE, omega, gyro_err)
    pathgen.acc_gen(RATE, f, acc_err)
    return 6 * n / (time.perf_counter() - t0)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=1.0)
    ap.add_argument("--compression", choices=("none", "lzf", "gzip"), default="none",
                    help="noise is incompressible: gzip-1 gives ~0.89 of the size at ~45 MB/s")
    ap.add_argument("--all-errors", action="store_true",
                    help="write every /imu/errors term (15 x 86 MB), not only gyro_bias and accel_bias")
    args = ap.parse_args(argv)
    n = int(args.hours * 3600 * RATE)
    axis_samples = 6 * n
    proc = psutil.Process()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "imu.h5"
        run_ours(2000, path, args.compression, args.all_errors)        # warm-up: numba compile / cache load
        t0 = time.perf_counter()
        t_imu, t_write, t_truth, n_sets = run_ours(n, path, args.compression, args.all_errors)
        total = time.perf_counter() - t0 - t_truth
        size = path.stat().st_size
    rss = proc.memory_info().rss
    peak = getattr(proc.memory_info(), "peak_wset", None) or _peak_rss()
    print(f"simkit.imu: {args.hours:g} h at {RATE:g} Hz, 6 axes, all terms, {n_sets} datasets "
          f"({args.compression}, {size / 1e6:.0f} MB)")
    print(f"  generation {t_imu:.2f} s + HDF5 write {t_write:.2f} s = {total:.2f} s "
          f"(truth synthesis {t_truth:.2f} s excluded) -> {axis_samples / total / 1e6:.1f} M axis-samples/s "
          f"(target >= 4 M, < 5 s)")
    print(f"  generation only: {axis_samples / t_imu / 1e6:.1f} M axis-samples/s; "
          f"RSS now {rss / 1e6:.0f} MB, peak {peak / 1e6:.0f} MB")

    compare(axis_samples / t_imu)
    return 0


def compare(ours_rate: float) -> None:
    """gnss-ins-sim's IMU error generation, allantools' flicker generator and allantools.oadev, timed in this run."""
    pathgen = peers.gnss_ins_sim()
    if pathgen is None:
        print("gnss-ins-sim not found (looked in: " + ", ".join(str(p) for p in peers.CANDIDATES) + ")")
    else:
        peer_rate = gnss_ins_sim_rate(pathgen, 200_000)
        print(f"gnss-ins-sim gyro_gen + acc_gen (bias, Gauss-Markov drift, white noise only), 200,000 samples: "
              f"{peer_rate / 1e6:.3f} M axis-samples/s -> simkit generation (every term) is "
              f"{ours_rate / peer_rate:.0f}x faster")

    import allantools

    m = 2**20
    t0 = time.perf_counter()
    allantools.noise.pink(m)
    t_pink = time.perf_counter() - t0
    from simkit.imu.noise import Flicker
    fl = Flicker(1e-5, 0.1, 1e4, 1.0 / RATE, np.random.default_rng(0), axes=1)
    fl.block(10)
    t0 = time.perf_counter()
    fl.block(m)
    t_fl = time.perf_counter() - t0
    print(f"flicker generation, {m} samples: allantools.noise.pink (Kasdin) {t_pink:.3f} s, "
          f"simkit Flicker {t_fl:.3f} s -> ratio {t_pink / t_fl:.1f}x "
          f"(allantools' generator is not streamable: whole record in memory)")

    y = np.random.default_rng(2).standard_normal(2_000_000)
    taus = np.logspace(-3, 2.5, 30)
    t0 = time.perf_counter()
    allantools.oadev(y, rate=RATE, data_type="freq", taus=taus)
    t_at = time.perf_counter() - t0
    t0 = time.perf_counter()
    adev(y, 1.0 / RATE, taus)
    t_ours = time.perf_counter() - t0
    print(f"overlapping ADEV, 2e6 samples, 30 taus: allantools.oadev {t_at:.3f} s, simkit adev {t_ours:.3f} s "
          f"-> ratio {t_at / t_ours:.1f}x")


def _peak_rss() -> int:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


if __name__ == "__main__":
    raise SystemExit(main())
