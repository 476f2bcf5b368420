"""Test helpers: a known drive (simkit's analytic generator) and writers of NMEA, GPX, KML and CSV logs of it.

The writers follow the formats' published definitions (NMEA 0183 GGA/RMC field order and XOR checksum, GPX 1.1,
KML 2.2 gx:Track); the NMEA output is checked against ``pynmea2`` in test_logs_readers.py.
"""
from datetime import datetime, timedelta, timezone

import numpy as np

from simkit.scenario import load
from simkit.trajectory import Trajectory

START = datetime(2026, 4, 27, 6, 0, 0, tzinfo=timezone.utc)

DRIVE = {
    "scenario": {"name": "drive", "start": "2026-04-27T06:00:00Z", "duration_s": 300.0, "seed": 7},
    "trajectory": {
        "rate_hz": 10.0, "origin": {"lat_deg": 52.5096, "lon_deg": 13.3760, "height_m": 80.0},
        "initial": {"speed_m_per_s": 8.0, "heading_deg": 30.0}, "coordinated_turns": False,
        "segment": [
            {"kind": "accelerate", "accel_m_per_s2": 1.0, "target_speed_m_per_s": 15.0},
            {"kind": "turn", "radius_m": 60.0, "angle_deg": 90.0},
            {"kind": "cruise", "duration_s": 20.0},
            {"kind": "weave", "heading_amplitude_deg": 10.0, "period_s": 20.0, "cycles": 2},
            {"kind": "turn", "radius_m": 80.0, "angle_deg": -120.0},
            {"kind": "accelerate", "accel_m_per_s2": 0.5, "target_speed_m_per_s": 10.0},
            {"kind": "climb", "flight_path_deg": 2.0, "pitch_rate_deg_per_s": 0.5},
            {"kind": "cruise", "duration_s": 200.0},
        ]},
}


def drive_truth(rate_hz=10.0, duration_s=300.0):
    sc = load(DRIVE, [f"trajectory.rate_hz={rate_hz}", f"scenario.duration_s={duration_s}"])
    blocks = list(Trajectory(sc.trajectory, sc.duration_s).blocks())
    return {k: np.concatenate([getattr(b, k) for b in blocks]) for k in blocks[0].arrays()}


def _checksum(body):
    c = 0
    for ch in body.encode():
        c ^= ch
    return f"{c:02X}"


def _sentence(body):
    return f"${body}*{_checksum(body)}"


def _dm(value, width, hemis):
    hemi = hemis[0] if value >= 0 else hemis[1]
    value = abs(value)
    deg = int(value)
    return f"{deg:0{width}d}{(value - deg) * 60:010.7f}", hemi


def nmea_lines(t_gps, lat_deg, lon_deg, h, vel_enu=None, geoid=30.0, rmc=True, start=START):
    """GGA (+ RMC) sentences; ``t_gps`` s since the UTC instant ``start``."""
    out = []
    for k in range(len(t_gps)):
        utc = start + timedelta(seconds=float(t_gps[k]))
        hms = f"{utc:%H%M%S}.{utc.microsecond // 10000:02d}"
        la, ns = _dm(lat_deg[k], 2, "NS")
        lo, ew = _dm(lon_deg[k], 3, "EW")
        out.append(_sentence(f"GPGGA,{hms},{la},{ns},{lo},{ew},1,12,0.8,{h[k] - geoid:.3f},M,{geoid:.3f},M,,"))
        if rmc:
            if vel_enu is not None:
                sp = np.hypot(vel_enu[k, 0], vel_enu[k, 1]) / (1852 / 3600)
                course = np.degrees(np.arctan2(vel_enu[k, 0], vel_enu[k, 1])) % 360
                v = f"{sp:.3f},{course:.3f}"
            else:
                v = ","
            out.append(_sentence(f"GPRMC,{hms},A,{la},{ns},{lo},{ew},{v},{utc:%d%m%y},,,A"))
    return out


def noisy_log(truth, every, sigma, seed=1, start_index=0):
    """Samples ``start_index::every`` of a truth with white noise of ``sigma`` m per ENU axis: (t, lat_deg,
    lon_deg, h, indices)."""
    import pymap3d

    idx = np.arange(start_index, len(truth["t"]), every)
    rng = np.random.default_rng(seed)
    lla = truth["pos_lla"][idx]
    e, n, u = (rng.normal(0.0, sigma, len(idx)) for _ in range(3))
    lat, lon, h = pymap3d.enu2geodetic(e, n, u, np.degrees(lla[:, 0]), np.degrees(lla[:, 1]), lla[:, 2])
    return truth["t"][idx], lat, lon, h, idx
