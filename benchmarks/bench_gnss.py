"""Benchmark: 24 h of GNSS observables at 1 Hz, GPS + BDS (~60 satellites), 3 antennas, 2 signals per
satellite (GPS L1C + L2W, BDS B1I + B3I), processed in blocks of 600 epochs (bounded memory).

Peer: gnss-lib-py's ``simulate_measures`` (code and Doppler only, GPS only, one receiver, no error terms),
timed on a short span of the same day and scaled to the same number of (epoch, antenna, satellite) triples.
Run: ``python benchmarks/bench_gnss.py [--hours H]``.
"""
from __future__ import annotations

import argparse
import resource
import time
from pathlib import Path

import numpy as np

from simkit import earth, frames, gpstime
from simkit.constellation import load_sky
from simkit.constellation.sources import DEFAULT_SKY, resolve
from simkit.gnss import GnssSimulator, parse_config
from simkit.section import Section

START = (2416, 86400.0)  # 2026-04-27 00:00 GPST, the day of the BRDM file
ORIGIN = np.radians([34.2, 108.9])


def sky_source() -> str:
    try:
        return str(resolve(DEFAULT_SKY))
    except Exception:
        return "nominal:gps+bds"


def ours(hours: float, block: int = 600):
    table = {"rate_hz": 1.0, "signals": ["L1C", "L2W", "B1I", "B3I"], "constellation": [{"source": sky_source()}],
             "clock": "per_antenna", "slip_rate_per_h": 0.5,
             "antenna": [{"lever_arm_m": [0.0, 0.0, 0.0]}, {"lever_arm_m": [3.965, 0.0, 0.0]},
                         {"lever_arm_m": [0.0, 9.445, 0.0]}]}
    cfg = parse_config(Section(table, "gnss"))
    t0 = time.perf_counter()
    sim = GnssSimulator(cfg, load_sky(cfg.sources), *START, seed=1, duration_s=hours * 3600.0)
    t = sim.epoch_times()
    pos = frames.lla_to_ecef(ORIGIN[0], ORIGIN[1], 400.0)
    rot = frames.attitude_from_euler(0.0, 0.0, 0.5)
    w_ib = rot.inv().apply(earth.earth_rate_enu(ORIGIN[0]))
    n_obs = 0
    for i in range(0, t.size, block):
        tb = t[i:i + block]
        m = tb.size
        out = sim.process(tb, np.tile(pos, (m, 1)), np.zeros((m, 3)), np.tile(rot.as_quat(), (m, 1)),
                          np.tile(w_ib, (m, 1)))
        for sig in cfg.signals:
            n_obs += int(np.isfinite(out.obs[sig].carrier).sum())
        del out
    return time.perf_counter() - t0, t.size, len(sim.sat_ids), n_obs


def peer(epochs: int = 60):
    """gnss-lib-py: seconds per (epoch, satellite) for code + Doppler of one GPS receiver."""
    import warnings

    from gnss_lib_py.navdata.navdata import NavData
    from gnss_lib_py.parsers.rinex_nav import RinexNav
    from gnss_lib_py.utils.gnss_models import simulate_measures

    nav_path = sky_source()
    if nav_path.endswith(".gz") or nav_path.startswith("nominal:"):
        import gzip
        import tempfile

        if nav_path.startswith("nominal:"):
            return None
        tmp = Path(tempfile.mkdtemp()) / Path(nav_path).with_suffix("").name
        tmp.write_bytes(gzip.open(nav_path).read())
        nav_path = str(tmp)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ephem = RinexNav(nav_path, satellites=[f"G{k:02d}" for k in range(1, 33)])
    pos = frames.lla_to_ecef(ORIGIN[0], ORIGIN[1], 400.0)
    state = NavData()
    for name, v in zip(("x_rx_m", "y_rx_m", "z_rx_m", "vx_rx_mps", "vy_rx_mps", "vz_rx_mps", "b_rx_m",
                        "b_dot_rx_mps"), list(pos) + [0.0] * 5):
        state[name] = np.array([v])
    rng = np.random.default_rng(0)
    ms0 = (START[0] * gpstime.SECONDS_PER_WEEK + START[1] + 3600.0) * 1000.0
    n_sv = 0
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for k in range(epochs):
            meas, _ = simulate_measures(ms0 + 1000.0 * k, state, ephem=ephem, rng=rng, el_mask=10.0)
            n_sv += len(meas)
    return (time.perf_counter() - t0) / max(n_sv, 1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=24.0)
    args = ap.parse_args()
    sec, m, s, n_obs = ours(args.hours)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    triples = n_obs / 4 * 2  # observations of one signal pair ~ (epoch, antenna, tracked satellite) triples
    print(f"simkit gnss: {args.hours:g} h at 1 Hz = {m} epochs, {s} satellites (GPS+BDS), 3 antennas, 2 signals "
          f"per satellite: {sec:.1f} s ({n_obs / sec / 1e6:.2f} M observations/s); peak RSS {rss:.0f} MB")
    if args.hours == 24.0:
        print(f"  target < 20 s: {'PASS' if sec < 20 else 'FAIL'}")
    try:
        per = peer()
    except Exception as exc:  # the peer is optional
        print(f"gnss-lib-py peer not run: {exc}")
        return
    if per is None:
        print("gnss-lib-py peer not run: no RINEX navigation file")
        return
    peer_sec = per * triples / 2
    print(f"gnss-lib-py simulate_measures (GPS code + Doppler, 1 signal, no error terms): {per * 1e6:.1f} us per "
          f"(epoch, satellite); the same {triples / 2:.3g} (epoch, antenna, satellite) triples would take "
          f"{peer_sec:.0f} s")
    print(f"ratio peer / simkit: {peer_sec / sec:.1f}x (simkit also produces carrier, C/N0, LLI, a second signal "
          f"and every error term)")


if __name__ == "__main__":
    main()
