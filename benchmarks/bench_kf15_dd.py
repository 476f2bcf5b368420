"""kf15_dd benchmark: the kf15 benchmark's hour of 100 Hz IMU with 1 Hz position/velocity fixes plus, at every
GNSS epoch, the fixed DD carrier of 2 baselines x 10 satellites (20 correlated rows), against pyins' feedback
filter on the same IMU and position/velocity data (pyins has no DD carrier measurement: the nearest peer loop),
in the same run. Also prints simkit's kf15 without the DD rows, the cost of the tightly coupled update.

DD rows: Wang 2018's baselines (0, 3.965, 0) and (9.445, 0, 0) m in the body, 11 fixed lines of sight, 3 mm
undifferenced carrier noise; covariance sigma^2 ([[2, 1], [1, 2]] (x) (I + 1 1^T)) (antenna 0 and the reference
shared). Figure: IMU samples per second.
Run: python benchmarks/bench_kf15_dd.py [--hours H] [--pyins-seconds S]
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_kf import CFG, data, pyins_run  # noqa: E402  (the kf15 benchmark's data and peer run)

from simkit.estimators import DDCarrier, ImuData, KalmanFilter15, KalmanFilter15DD  # noqa: E402

BASE = np.array([[0.0, 3.965, 0.0], [9.445, 0.0, 0.0]])
SIGMA = 0.003


def dd_rows(t, quat_nb, n_sat=11, seed=1):
    rng = np.random.default_rng(seed)
    az, el = rng.uniform(0, 2 * np.pi, n_sat), rng.uniform(0.3, 1.5, n_sat)
    e = np.column_stack([np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)])
    ref = np.argmax(el)
    g1 = -(np.delete(e, ref, 0) - e[ref])  # (n, 3)
    n = g1.shape[0]
    los, base = np.tile(g1, (2, 1)), np.repeat(BASE, n, axis=0)
    cov = SIGMA**2 * np.kron([[2.0, 1.0], [1.0, 2.0]], np.eye(n) + np.ones((n, n)))
    c = Rotation.from_quat(quat_nb).as_matrix()
    z = np.einsum("mi,ij,mj->m", los, c, base)
    noise = rng.multivariate_normal(np.zeros(2 * n), cov, size=t.size)
    m = 2 * n
    return DDCarrier(t, np.arange(t.size + 1) * m, np.tile(los, (t.size, 1)), np.tile(base, (t.size, 1)),
                     (z + noise).ravel(), np.tile(cov.ravel(), t.size))


def timed(cls, imu, gnss, init, **kw):
    short = ImuData(imu.t[:200], imu.gyro[:200], imu.accel[:200])
    cls(CFG, init).run(short, gnss, **kw)  # load the compiled kernels
    start = time.perf_counter()
    cls(CFG, init).run(imu, gnss, **kw)
    return time.perf_counter() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=1.0)
    ap.add_argument("--pyins-seconds", type=float, default=30.0)
    a = ap.parse_args()
    imu, gnss, init = data(a.hours * 3600.0)
    dd = dd_rows(gnss.t, init.quat_nb)
    n = imu.t.size
    wall = timed(KalmanFilter15DD, imu, gnss, init, dd=dd)
    base = timed(KalmanFilter15, imu, gnss, init)
    print(f"simkit kf15_dd: {n} IMU samples, {gnss.t.size} fixes + {dd.range_m.size} DD rows in {wall:.2f} s = "
          f"{n / wall:,.0f} samples/s")
    print(f"simkit kf15 (no DD rows): {base:.2f} s = {n / base:,.0f} samples/s (DD update cost x{wall / base:.2f})")
    pw, pn = pyins_run(imu, gnss, init, a.pyins_seconds)
    print(f"pyins run_feedback_filter: {pn} IMU samples ({a.pyins_seconds:g} s of the same data) in {pw:.2f} s = "
          f"{pn / pw:,.0f} samples/s")
    print(f"ratio simkit kf15_dd / pyins (samples per second): {(n / wall) / (pn / pw):,.0f}x")


if __name__ == "__main__":
    main()
