"""Scoring benchmark: an estimate at 100 Hz against the 100 Hz truth of airborne_stim300 (1000 s, 100 001
epochs, every estimate epoch half a sample off the truth grid so that every epoch is interpolated).

Ours: simkit.referee.score (Hermite position / linear velocity / slerp attitude interpolation, ENU errors,
Euler and misalignment attitude errors, statistics, convergence, NEES over 6 states).
Peer, same run, same data: pyins.transform.compute_state_difference (linear / slerp resampling, NED errors;
no statistics or NEES), given the pandas frames it expects (their construction is not timed).
Run: python benchmarks/bench_score.py [--duration S]
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import pymap3d
from pyins import transform as pyins_transform
from scipy.spatial.transform import Rotation

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing

import simkit  # noqa: E402
from simkit import referee  # noqa: E402
from simkit.solution import Solution  # noqa: E402
from timing import best_of  # noqa: E402  (benchmarks/timing.py)

SWAP = np.array([[0.0, 1, 0], [1, 0, 0], [0, 0, -1]])


def _pyins_frame(t, pos_ecef, vel_enu, quat):
    lat, lon, h = pymap3d.ecef2geodetic(*pos_ecef.T, deg=True)
    rph = Rotation.from_matrix(SWAP @ Rotation.from_quat(quat).as_matrix() @ SWAP).as_euler("ZYX", True)
    vel = vel_enu @ SWAP.T
    return pd.DataFrame({"lat": lat, "lon": lon, "alt": h, "VN": vel[:, 0], "VE": vel[:, 1], "VD": vel[:, 2],
                         "roll": rph[:, 2], "pitch": rph[:, 1], "heading": np.mod(rph[:, 0], 360)}, index=t)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--duration", type=float, default=1000.0, help="seconds of airborne_stim300 (default 1000)")
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        path = simkit.run("airborne_stim300", out=Path(tmp) / "air.h5",
                          overrides=[f"scenario.duration_s={args.duration}"])
        truth = referee.read_truth(path)
    k = len(truth.t) - 1
    mid = referee.truth_at(truth, truth.t[:-1] + 0.005)
    rng = np.random.default_rng(0)
    cov = np.broadcast_to(np.eye(6), (k, 6, 6)).copy()
    sol = Solution(t=mid.t, pos_ecef=mid.pos_ecef + rng.standard_normal((k, 3)), vel_enu=mid.vel_enu,
                   quat_nb=mid.quat_nb, cov=cov, state_names=("pos_e", "pos_n", "pos_u", "vel_e", "vel_n", "vel_u"))
    ours = best_of(lambda: referee.score(truth, sol))
    est = _pyins_frame(sol.t, sol.pos_ecef, sol.vel_enu, sol.quat_nb)
    ref = _pyins_frame(truth.t, truth.pos_ecef, truth.vel_enu, truth.quat_nb)
    peer = best_of(lambda: pyins_transform.compute_state_difference(est, ref))
    print(f"score {k} epochs against {len(truth.t)} truth samples")
    print(f"  simkit.referee.score                     {ours * 1e3:8.1f} ms  {k / ours / 1e6:6.2f} M epochs/s")
    print(f"  pyins compute_state_difference (peer)    {peer * 1e3:8.1f} ms  {k / peer / 1e6:6.2f} M epochs/s")
    print(f"  ratio (peer time / ours)                 {peer / ours:8.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
