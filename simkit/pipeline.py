"""``simkit.run``: scenario -> trajectory truth -> IMU -> GNSS observables -> one HDF5 file, block by block."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .io.writer import Writer
from .scenario import load
from .trajectory import Trajectory

BLOCK_SAMPLES = 1 << 16


def run(scenario, out=None, seed=None, overrides=None, progress=False, block_samples: int = BLOCK_SAMPLES) -> Path:
    """Simulate a scenario into ``out`` (default ``<scenario name>.h5``); returns the output path."""
    sc = load(scenario, overrides)
    seed = sc.seed if seed is None else int(seed)
    out = Path(out) if out is not None else Path(f"{sc.name}.h5")
    traj = Trajectory(sc.trajectory, sc.duration_s)
    rate = sc.trajectory.rate_hz
    n_total = traj.n_samples()

    imu = gnss = None
    if sc.imu is not None:
        from .imu import ImuSimulator

        imu = ImuSimulator(sc.imu, rate, seed)
    if sc.gnss is not None:
        from .gnss import GnssSimulator

        gnss = GnssSimulator(sc.gnss, sc.start_week, sc.start_sow, seed, sc.duration_s)
        stride = int(round(rate / sc.gnss.rate_hz))

    attrs = {"scenario_toml": sc.text, "seed": seed, "start_gps_week": sc.start_week,
             "start_gps_sow": sc.start_sow, "scenario_name": sc.name,
             "overrides": json.dumps(sc.overrides)}
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=n_total, unit="sample", unit_scale=True, desc=sc.name, leave=False)
    with Writer(out, attrs) as w:
        w.group_attrs("truth", {"rate_hz": rate})
        if imu is not None:
            w.group_attrs("imu", dict(imu.attributes(), rate_hz=rate))
        if gnss is not None:
            w.group_attrs("gnss", {"rate_hz": sc.gnss.rate_hz})
            for name, (data, units) in gnss.static_datasets().items():
                w.write(f"gnss/{name}", data, units)
        k = 0
        for truth in traj.blocks(block_samples=block_samples):
            for name, data in truth.arrays().items():
                w.append(f"truth/{name}", data, truth.UNITS[name])
            if imu is not None:
                block = imu.process(truth.t, truth.omega_ib_b, truth.f_ib_b)
                gyro, accel, errors = block
                w.append("imu/t", truth.t, "s")
                w.append("imu/gyro", gyro, "rad/s")
                w.append("imu/accel", accel, "m/s^2")
                for name, data in block.increments.items():
                    w.append(f"imu/{name}", data, "rad" if name == "dtheta" else "m/s")
                for name, data in errors.items():
                    w.append(f"imu/errors/{name}", data, "rad/s" if name.startswith("gyro") else "m/s^2")
            if gnss is not None:
                idx = np.nonzero((np.arange(k, k + len(truth)) % stride) == 0)[0]
                if len(idx):
                    sub = truth.take(idx)
                    for name, (data, units) in gnss.process(sub.t, sub.pos_ecef, sub.vel_ecef(), sub.quat_nb,
                                                            sub.omega_ib_b).items():
                        w.append(f"gnss/{name}", data, units)
            k += len(truth)
            if bar is not None:
                bar.update(len(truth))
    if bar is not None:
        bar.close()
    return out
