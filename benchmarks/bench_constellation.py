"""Constellation benchmarks, each against a peer measured in the same run.

1. Parsing the 2026 merged BRDM navigation file (1.3 MB gzip, 8.2 MB of text): simkit vs georinex
   (georinex reads the same .gz directly, restricted to GPS + BDS like simkit).
2. Satellite states: broadcast-ephemeris positions + clocks for many satellite-epochs vs skyfield's SGP4
   (EarthSatellite.at(...).frame_xyz(itrs), same satellite-epoch count).
3. ``simkit sky`` working memory per satellite-epoch (tracemalloc peak of the geometry and DOPs), the figure
   behind its memory estimate (``simkit.commands.sky.BYTES_PER_SAT_EPOCH``).

Run: python benchmarks/bench_constellation.py
"""
from __future__ import annotations

import warnings

import numpy as np

from simkit import constellation as sc
from simkit.constellation.sources import DATA_DIR, resolve
from timing import best_of  # benchmarks/timing.py


def bench_parse():
    path = resolve(sc.DEFAULT_SKY)
    ours = best_of(lambda: sc.load(path), 3)
    import georinex

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        peer = best_of(lambda: georinex.load(path, use={"G", "C"}), 1)
        peer_all = best_of(lambda: georinex.load(path), 1)
    print(f"parse {path.name} (1.3 MB gzip, 8.2 MB text; simkit checks every record, keeps GPS + BDS):")
    print(f"  simkit {ours:.3f} s | georinex GPS+BDS {peer:.2f} s, ratio {peer / ours:.1f}x (target >= 10x) | "
          f"georinex all systems {peer_all:.2f} s, ratio {peer_all / ours:.1f}x")


def bench_states():
    c = sc.load(sc.DEFAULT_SKY)
    s = len(c.sat_ids)
    sow = 86400.0 + np.linspace(0.0, 86000.0, 40000)
    c.state(2416, sow[:10])  # JIT warm-up (numba cache)
    n = sow.size * s
    ours = best_of(lambda: c.state(2416, sow), 3)
    ours_v = best_of(lambda: c.state(2416, sow, velocity=True), 3)
    from skyfield.api import EarthSatellite
    from skyfield.framelib import itrs

    from simkit import gpstime

    tle = (DATA_DIR / "gps-ops_2025-11-21.txt").read_text().splitlines()
    sat = EarthSatellite(tle[1], tle[2], tle[0], gpstime.timescale())
    ts = gpstime.timescale()
    jd = np.full(n, 2461000.5)
    frac = np.linspace(0.0, 1.0, n)
    sgp4 = best_of(lambda: sat.model.sgp4_array(jd, frac), 3)
    # the full skyfield chain (SGP4 + TEME -> ITRS with fresh Time objects) is ~100x slower: timed on 100,000
    n_full = 100_000
    full = best_of(lambda: sat.at(ts.tai_jd(jd[:n_full], frac[:n_full] + 0.5)).frame_xyz(itrs), 1)
    print(f"states: {n:,} satellite-epochs ({s} satellites x {sow.size} epochs)")
    print(f"  simkit broadcast pos+clock (ECEF)     {n / ours / 1e6:6.2f} M/s  ({ours:.3f} s; target >= 2 M/s)")
    print(f"  simkit with velocity + drift          {n / ours_v / 1e6:6.2f} M/s  ({ours_v:.3f} s)")
    print(f"  skyfield SGP4 (sgp4_array, TEME only) {n / sgp4 / 1e6:6.2f} M/s  ({sgp4:.3f} s)   "
          f"ratio {sgp4 / ours:.1f}x")
    print(f"  skyfield SGP4 + TEME->ITRS (at().frame_xyz) {n_full / full / 1e6:6.3f} M/s "
          f"(timed on {n_full:,}; ratio {(n / ours) / (n_full / full):.0f}x)")


def bench_sky_memory():
    import argparse
    import tracemalloc

    from simkit.commands import sky

    args = argparse.Namespace(lat=34.25, lon=108.95, height=400.0, mask=10.0)
    m = 4000
    sow = 86400.0 + np.arange(m) * (86400.0 / m)
    print(f"sky working memory ({m} epochs; the estimate uses {sky.BYTES_PER_SAT_EPOCH} B per satellite-epoch):")
    for source in (sc.DEFAULT_SKY, "nominal:gps"):
        const = sc.load(source)
        sky._compute(const, args, 2416, sow[:10])  # JIT warm-up outside the trace
        tracemalloc.start()
        sky._compute(const, args, 2416, sow)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        print(f"  {source}: {len(const)} satellites, peak {peak / 2**20:.1f} MiB = "
              f"{peak / (m * len(const)):.0f} B per satellite-epoch")


if __name__ == "__main__":
    bench_parse()
    bench_states()
    bench_sky_memory()
