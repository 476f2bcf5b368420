"""Freeze the truth and IMU arrays of high_dynamic (20 s at 100 Hz, STIM300, no GNSS) made by the simkit on the path:
``PYTHONPATH=OLD_TREE python tests/data/frozen/freeze_truth_imu.py OUT.npz`` (tests/data/SOURCES.md)."""
import sys
import tempfile
import tomllib
from pathlib import Path

import h5py
import numpy as np
import tomli_w

import simkit

data = tomllib.loads((Path(simkit.__file__).parent / "scenarios" / "high_dynamic.toml").read_text())
data.pop("gnss"); data["scenario"]["duration_s"] = 20.0; data["imu"] = {"preset": "stim300"}
with tempfile.TemporaryDirectory() as tmp:
    p = Path(tmp) / "s.toml"; p.write_text(tomli_w.dumps(data))
    out = simkit.run(str(p), out=Path(tmp) / "s.h5")
    arrays = {}
    with h5py.File(out, "r") as f:
        for g in ("truth", "imu"):
            for k in ("t", "pos_ecef", "pos_lla", "vel_enu", "quat_nb", "euler", "omega_ib_b", "f_ib_b", "gyro", "accel"):
                if f"{g}/{k}" in f: arrays[f"{g}/{k}"] = f[f"{g}/{k}"][()]
np.savez_compressed(sys.argv[1], **{k.replace("/", "."): v for k, v in arrays.items()})
print(sorted(arrays), simkit.__file__)
