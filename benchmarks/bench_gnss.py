"""Benchmark: 24 h of GNSS observables at 1 Hz, GPS + BDS (~60 satellites), 3 antennas, 2 signals per
satellite (GPS L1C + L2W, BDS B1I + B3I), processed in blocks of 600 epochs (bounded memory).

Peer: gnss-lib-py's ``simulate_measures`` (code and Doppler only, GPS only, one receiver, no error terms),
timed on a short span of the same day and scaled to the same number of (epoch, antenna, satellite) triples. It runs
in its own interpreter (``GNSS_LIB_PY_PYTHON``; see ``peer_gnss_lib_py.py`` for why).
Run: ``python benchmarks/bench_gnss.py [--hours H]``.
"""
from __future__ import annotations

import argparse
import resource
import time
from pathlib import Path

import numpy as np

from simkit import frames, gpstime
from simkit.constellation import load_sky
from simkit.constellation.sources import resolve
from simkit.gnss import GnssSimulator
from simkit.scenario import load
from simkit.trajectory import Trajectory

START = (2416, 86400.0)  # 2026-04-27 00:00 GPST, the day of the BRDM file
ORIGIN = np.radians([34.2, 108.9])
BRDM = "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"
SIGNALS = ["L1C", "L2W", "B1I", "B3I"]


def sky_source() -> str:
    try:
        return str(resolve(BRDM))
    except Exception:
        return "nominal:gps+bds"


def scenario(hours: float):
    """xian_static_bds on 27 Apr 2026 with the bundled broadcast file, GPS + BDS, two signals per satellite."""
    return load("xian_static_bds", [f"scenario.duration_s={hours * 3600:g}",
                                    'scenario.start="2026-04-27T00:00:00Z"',
                                    f"gnss.constellation[0].source={sky_source()!r}",
                                    f"gnss.signals={SIGNALS!r}"])


def ours(hours: float, block: int = 600, ahead: bool = True):
    """(wall s, CPU s, epochs, satellites, observations) of the observables stage, blocks of ``block`` epochs,
    as the pipeline runs it (sky of the scenario's systems, trajectory truth at the GNSS rate; ``ahead``: the
    next block's geometry on a second thread, ``GnssSimulator.process_blocks``)."""
    from simkit.heap import keep_freed_memory

    keep_freed_memory()  # as simkit.run does for its process
    sc = scenario(hours)
    t0, c0 = time.perf_counter(), time.process_time()
    sky = load_sky(sc.gnss.sources, sc.gnss.nav_systems)
    sim = GnssSimulator(sc.gnss, sky, sc.start_week, sc.start_sow, sc.seed, sc.duration_s)
    n_obs = m = 0
    blocks = ((tr.t, tr.pos_ecef, tr.vel_ecef(), tr.quat_nb, tr.omega_ib_b)
              for tr in Trajectory(sc.trajectory, sc.duration_s).blocks(rate_hz=sc.gnss.rate_hz, block_samples=block))
    for out in sim.process_blocks(blocks, ahead=ahead):
        for sig in sc.gnss.signals:
            n_obs += int(np.isfinite(out.obs[sig].carrier).sum())
        m += out.t.size
        del out
    return time.perf_counter() - t0, time.process_time() - c0, m, len(sim.sat_ids), n_obs


def peer(epochs: int = 60):
    """gnss-lib-py: seconds per (epoch, satellite) for code + Doppler of one GPS receiver, run by
    ``peer_gnss_lib_py.py`` in the interpreter ``GNSS_LIB_PY_PYTHON`` names (default: this one)."""
    import gzip
    import os
    import subprocess
    import sys
    import tempfile

    nav_path = sky_source()
    if nav_path.startswith("nominal:"):
        return None
    if nav_path.endswith(".gz"):
        tmp = Path(tempfile.mkdtemp()) / Path(nav_path).with_suffix("").name
        tmp.write_bytes(gzip.open(nav_path).read())
        nav_path = str(tmp)
    pos = frames.lla_to_ecef(ORIGIN[0], ORIGIN[1], 400.0)
    ms0 = (START[0] * gpstime.SECONDS_PER_WEEK + START[1] + 3600.0) * 1000.0
    python = os.environ.get("GNSS_LIB_PY_PYTHON", sys.executable)
    out = subprocess.run([python, str(Path(__file__).with_name("peer_gnss_lib_py.py")), nav_path,
                          *map(repr, map(float, pos)), repr(ms0), str(epochs)], capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"{python}: {out.stderr.strip().splitlines()[-1] if out.stderr.strip() else 'failed'} "
                           f"(give an interpreter with gnss-lib-py in GNSS_LIB_PY_PYTHON)")
    return float(out.stdout.split()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=24.0)
    args = ap.parse_args()
    ours(0.05)  # compiled kernels loaded, caches warm: the figure is the steady state
    sec, cpu, m, s, n_obs = ours(args.hours)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    triples = n_obs / 2  # two signals per satellite: (epoch, antenna, tracked satellite) triples
    print(f"simkit gnss: xian_static_bds {args.hours:g} h at 1 Hz = {m} epochs, {s} satellites (GPS+BDS, {BRDM}), "
          f"3 antennas, 2 signals per satellite: {sec:.1f} s wall, {cpu:.1f} s CPU ({n_obs / sec / 1e6:.2f} M "
          f"observations/s); peak RSS {rss:.0f} MB")
    if args.hours == 24.0:
        print(f"  target < 10 s: {'PASS' if sec < 10 else 'FAIL'} (wall), {'PASS' if cpu < 10 else 'FAIL'} (CPU)")
    try:
        per = peer()
    except Exception as exc:  # the peer is optional
        print(f"gnss-lib-py peer not run: {exc}")
        return
    if per is None:
        print("gnss-lib-py peer not run: no RINEX navigation file")
        return
    peer_sec = per * triples
    print(f"gnss-lib-py simulate_measures (GPS code + Doppler, 1 signal, no error terms): {per * 1e6:.1f} us per "
          f"(epoch, satellite); the same {triples:.3g} (epoch, antenna, satellite) triples would take "
          f"{peer_sec:.0f} s")
    print(f"ratio peer / simkit: {peer_sec / sec:.1f}x (wall; simkit also produces carrier, C/N0, LLI, a second "
          f"signal and every error term)")


if __name__ == "__main__":
    main()
