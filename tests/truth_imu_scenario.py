"""The truth + IMU scenario of issue 25's benchmark, shortened for tests: the bundled high_dynamic flight without
its [gnss] table, with the STIM300 IMU (every error term)."""
import tomllib
from pathlib import Path

import tomli_w

import simkit


def truth_imu_toml(folder: Path, duration_s: float) -> Path:
    """The scenario, ``duration_s`` long at high_dynamic's rate (100 Hz), written to ``folder``; its path."""
    data = tomllib.loads((Path(simkit.__file__).parent / "scenarios" / "high_dynamic.toml").read_text())
    data.pop("gnss")
    data["scenario"]["duration_s"] = float(duration_s)
    data["imu"] = {"preset": "stim300"}
    path = Path(folder) / "truth_imu.toml"
    path.write_text(tomli_w.dumps(data))
    return path
