"""Benchmark: truth generation for 1 h at 1 kHz including the HDF5 write (target >= 1,000,000 samples/s,
peak RSS < 1 GB).

The peer, gnss-ins-sim, is not installable from PyPI here, so the comparison runs a per-sample reference
generator in the style such tools use (one Python step per sample: Euler-angle kinematics, n-frame velocity and
position update, gravity), clearly labelled, on a shorter record, and prints the ratio.
Run: python benchmarks/bench_truth.py [--seconds 3600] [--rate 1000]
"""
from __future__ import annotations

import argparse
import math
import tempfile
import time
from pathlib import Path

import numpy as np
import psutil

from simkit import earth
from simkit.pipeline import run
from simkit.scenario.loader import load

HIGH_DYNAMIC = Path(__file__).resolve().parents[1] / "scenarios" / "high_dynamic.toml"


def per_sample_reference(n: int, rate: float) -> float:
    """A per-sample loop generator (the architecture of gnss-ins-sim-like tools); returns samples/s."""
    h = 1.0 / rate
    lat, lon, hgt = math.radians(40.0), math.radians(116.0), 4000.0
    v = np.array([100.0, 200.0, 0.0])
    att = np.zeros(3)
    t0 = time.perf_counter()
    for k in range(n):
        rate_cmd = np.array([0.0, 0.1 * math.sin(k * h), 0.05])
        att = att + rate_cmd * h
        rm, rn = earth.radii(lat)
        g = earth.normal_gravity(lat, hgt)
        acc = np.array([0.1, 0.0, 0.0])
        w_ie = np.array([0.0, earth.OMEGA_E * math.cos(lat), earth.OMEGA_E * math.sin(lat)])
        w_en = np.array([-v[1] / (rm + hgt), v[0] / (rn + hgt), v[0] * math.tan(lat) / (rn + hgt)])
        f_n = acc + np.cross(2 * w_ie + w_en, v) + np.array([0.0, 0.0, g])
        c = np.cos(att)
        s = np.sin(att)
        _ = np.array([[c[2], -s[2], 0], [s[2], c[2], 0], [0, 0, 1]]) @ f_n
        v = v + acc * h
        lat += v[1] / (rm + hgt) * h
        lon += v[0] / ((rn + hgt) * math.cos(lat)) * h
        hgt += v[2] * h
    return n / (time.perf_counter() - t0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=3600.0)
    ap.add_argument("--rate", type=float, default=1000.0)
    args = ap.parse_args()
    sc = load(HIGH_DYNAMIC)
    data = dict(sc.data)
    data = {"scenario": dict(data["scenario"], duration_s=args.seconds),
            "trajectory": dict(data["trajectory"], rate_hz=args.rate)}  # truth only: no IMU / GNSS sections
    proc = psutil.Process()
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "truth.h5"
        t0 = time.perf_counter()
        run(data, out=out)
        dt = time.perf_counter() - t0
        n = int(args.seconds * args.rate) + 1
        size = out.stat().st_size
    peak = proc.memory_info().rss
    try:
        import resource

        peak = max(peak, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)
    except ImportError:
        pass
    ours = n / dt
    ref = per_sample_reference(20000, args.rate)
    print(f"simkit truth + HDF5 write: {n} samples in {dt:.2f} s = {ours:,.0f} samples/s "
          f"(file {size / 1e6:.0f} MB, peak RSS {peak / 2**20:.0f} MiB)")
    print(f"per-sample loop reference (gnss-ins-sim-style, not installable here): {ref:,.0f} samples/s")
    print(f"ratio simkit / per-sample reference: {ours / ref:.1f}x")
    print(f"target >= 1,000,000 samples/s: {'met' if ours >= 1e6 else 'NOT met'}; "
          f"peak RSS < 1 GiB: {'met' if peak < 2**30 else 'NOT met'}")


if __name__ == "__main__":
    main()
