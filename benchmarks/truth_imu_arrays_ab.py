"""Every array of the truth + IMU run of issue 25 (bench_truth_imu.scenario: 600 s at 1 kHz, STIM300) from two
checkouts, compared: for each dataset the largest difference in its units and relative to its largest value,
or "identical"; the Euler triple away from 90 deg of pitch (where the old conversion lost digits).

    python benchmarks/truth_imu_arrays_ab.py OLD_TREE NEW_TREE [--seconds 600]
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_truth_imu  # noqa: E402


def run(tree: str, scenario: Path, out: Path) -> None:
    subprocess.run([sys.executable, "-m", "simkit", "run", str(scenario), "-o", str(out), "-q"], cwd=tree, check=True)


def compare(old: Path, new: Path) -> list[tuple[str, str]]:
    rows = []
    with h5py.File(old, "r") as a, h5py.File(new, "r") as b:
        names = []
        a.visititems(lambda name, obj: names.append(name) if isinstance(obj, h5py.Dataset) else None)
        for name in names:
            x, y = a[name][()], b[name][()]
            if x.shape != y.shape or x.dtype != y.dtype:
                rows.append((name, f"DIFFERENT LAYOUT {x.shape} {x.dtype} / {y.shape} {y.dtype}"))
            elif np.array_equal(x, y):
                rows.append((name, "identical"))
            elif name == "truth/euler":
                away = np.cos(x[:, 0]) > 0.01
                diff = (y - x + np.pi) % (2.0 * np.pi) - np.pi
                rows.append((name, f"{np.abs(diff[away]).max():.1e} rad away from 90 deg of pitch"))
            else:
                d = np.abs(y - x).max()
                rows.append((name, f"{d:.1e} ({d / np.abs(x).max():.1e} of its largest value)"))
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--seconds", type=float, default=600.0)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="truth_imu_ab_") as tmp:
        scenario = Path(tmp) / "s.toml"
        scenario.write_text(bench_truth_imu.scenario(args.seconds, 1000.0))
        run(args.old, scenario, Path(tmp) / "old.h5")
        run(args.new, scenario, Path(tmp) / "new.h5")
        for name, text in compare(Path(tmp) / "old.h5", Path(tmp) / "new.h5"):
            print(f"{name:<40} {text}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
