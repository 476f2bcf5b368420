"""Cost of a logged trajectory: the P-spline fit of a 100 Hz log over 1000 s (100 000 samples, 0.5 m noise) and
the evaluation of the truth at 99 000 epochs, in CPU seconds.

Run: python benchmarks/bench_log_fit.py
"""
import time

import numpy as np

from simkit import frames
from simkit.trajectory.logged import FitOptions, LoggedPath, Track


def main():
    n = 100_000
    t = np.arange(n) * 0.01
    rng = np.random.default_rng(0)
    enu = np.stack([20 * t + 50 * np.sin(t / 30), 300 * np.cos(t / 50), 0.01 * t], -1) + rng.normal(0, 0.5, (n, 3))
    lat0, lon0 = np.radians(52.5), np.radians(13.4)
    pos = frames.lla_to_ecef(lat0, lon0, 80.0) + frames.enu_to_ecef_vec(enu, lat0, lon0)
    track = Track(t, pos, np.arange(n), "synthetic")
    c0 = time.process_time()
    path = LoggedPath(track, FitOptions(position_sigma_m=(0.5, 0.5, 0.5)), 990.0)
    fit = time.process_time() - c0
    c0 = time.process_time()
    path.truth(np.arange(99_000) * 0.01)
    print(f"fit of {n} samples: {fit:.2f} s CPU; truth at 99000 epochs: {time.process_time() - c0:.2f} s CPU")


if __name__ == "__main__":
    main()
