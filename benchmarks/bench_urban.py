"""Benchmark: line-of-sight states for 1 h at 10 Hz (36,001 epochs), 3 antennas, GPS + BDS, along a 2 km street
lined with 200 buildings (a GeoJSON city block: 100 footprints each side, 20 m x 15 m, 15-60 m high).

Times, on the same scenario: the whole ``simkit run`` (truth at 10 Hz, no IMU, L1C + B1I observables to HDF5)
with the environment and without it, and the environment's own share (the ray tests: ``Environment.classify``
over every block of the run), as CPU and wall seconds. The car drives the 2 km street once in the hour.
Run: ``python benchmarks/bench_urban.py [--minutes MIN]``.
"""
from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np
import pymap3d

import simkit
from simkit.environment import Environment

ORIGIN = {"lat_deg": 34.2, "lon_deg": 108.9, "height_m": 400.0}


def city(path: Path, n_per_side: int = 100, street_m: float = 2000.0, seed: int = 3) -> None:
    """A north-south street 24 m wide with ``n_per_side`` buildings each side, written as GeoJSON."""
    rng = np.random.default_rng(seed)
    step = street_m / n_per_side
    feats = []
    for side in (-1.0, 1.0):
        for k in range(n_per_side):
            n0, n1 = k * step + 0.5, (k + 1) * step - 0.5
            e0, e1 = side * 12.0, side * 27.0
            e = np.array([e0, e1, e1, e0, e0])
            n = np.array([n0, n0, n1, n1, n0])
            lat, lon, _ = pymap3d.enu2geodetic(e, n, 0.0, ORIGIN["lat_deg"], ORIGIN["lon_deg"], ORIGIN["height_m"])
            feats.append({"type": "Feature", "properties": {"height": float(rng.uniform(15.0, 60.0))},
                          "geometry": {"type": "Polygon", "coordinates": [np.stack([lon, lat], 1).tolist()]}})
    path.write_text(json.dumps({"type": "FeatureCollection", "features": feats}))


def scenario(minutes: float, buildings: str | None) -> dict:
    dur = minutes * 60.0
    sc = {"scenario": {"name": "bench_urban", "start": "2026-04-27T06:00:00Z", "duration_s": dur},
          "trajectory": {"rate_hz": 10.0, "origin": ORIGIN, "initial": {"speed_m_per_s": 2000.0 / dur},
                         "segment": [{"kind": "cruise", "duration_s": dur}]},
          "gnss": {"rate_hz": 10.0, "signals": ["L1C", "B1I"],
                   "constellation": [{"source": "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"}],
                   "antenna": [{"lever_arm_m": [0.0, 1.0, 1.5]}, {"lever_arm_m": [0.0, -1.0, 1.5]},
                               {"lever_arm_m": [0.8, 0.0, 1.5]}]}}
    if buildings:
        sc["environment"] = {"buildings": buildings}
    return sc


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--minutes", type=float, default=60.0)
    args = ap.parse_args()
    spent = {"wall": 0.0, "cpu": 0.0, "rays": 0}
    original = Environment.classify

    def timed(self, *a, **k):
        w, c = time.perf_counter(), time.process_time()
        out = original(self, *a, **k)
        spent["wall"] += time.perf_counter() - w
        spent["cpu"] += time.process_time() - c
        spent["rays"] += out.state.size
        return out

    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        city(d / "city.geojson")
        # warm-up: numba compiles (or loads its cache) once, outside the timings
        simkit.run(scenario(0.1, str(d / "city.geojson")), out=d / "warm.h5")
        Environment.classify = timed
        rows = {}
        for label, b in (("with 200 buildings", str(d / "city.geojson")), ("open sky", None)):
            w, c = time.perf_counter(), time.process_time()
            out = simkit.run(scenario(args.minutes, b), out=d / "run.h5")
            rows[label] = (time.perf_counter() - w, time.process_time() - c)
            out.unlink()
        Environment.classify = original
    print(f"{args.minutes:g} min at 10 Hz, 3 antennas, L1C + B1I, 2 km street with 200 buildings (800 walls)")
    for label, (w, c) in rows.items():
        print(f"  simkit run, {label:20s}: {w:7.1f} s wall, {c:7.1f} s CPU")
    print(f"  environment (ray tests) : {spent['wall']:7.1f} s wall, {spent['cpu']:7.1f} s CPU for "
          f"{spent['rays']:,} (epoch, antenna, satellite) rays")


if __name__ == "__main__":
    main()
