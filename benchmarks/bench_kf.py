"""KF15 benchmark: 1 h of 100 Hz IMU with 1 Hz GNSS position/velocity fixes, against pyins' feedback filter on
the same data, in the same run.

The data are a static IMU at 34.2 N (normal gravity and Earth rate in body axes, turned by a fixed attitude)
with white noise and turn-on biases, and GNSS fixes of the true antenna position plus noise: the filters do the
same work per sample whatever the motion. simkit's kf15 runs the whole hour (after one short warm-up call that
loads the compiled numba kernels); pyins, much slower per sample, runs the first ``--pyins-seconds`` of the same
data and the figure compared is IMU samples per second.
Run: python benchmarks/bench_kf.py [--hours H] [--pyins-seconds S]
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing

from simkit import earth
from simkit.estimators import FilterConfig, GnssFixes, ImuData, InitialState, KalmanFilter15
from simkit.frames import lla_to_ecef

RATE, GNSS_RATE = 100.0, 1.0
LLA = np.array([np.radians(34.2), np.radians(108.9), 400.0])
LEVER = np.array([0.3, 1.0, 1.2])
CFG = FilterConfig(gyro_arw=2.9e-5, accel_vrw=8.3e-4, p0_att=(0.005, 0.005, 0.02), p0_vel=0.1,
                   p0_pos=(2.0, 2.0, 3.0), p0_gyro_bias=4.8e-5, p0_accel_bias=9.8e-3)


def data(seconds, seed=0):
    rng = np.random.default_rng(seed)
    n = int(seconds * RATE) + 1
    t = np.arange(n) / RATE
    rot = Rotation.from_euler("zxy", [-0.7, 0.02, -0.01])  # C_b^n = Rz(-heading) Rx(pitch) Ry(roll)
    w_b = rot.inv().apply(earth.earth_rate_enu(LLA[0]))
    f_b = rot.inv().apply([0.0, 0.0, earth.normal_gravity(LLA[0], LLA[2])])
    gyro = w_b + rng.normal(size=3) * CFG.p0_gyro_bias + rng.normal(size=(n, 3)) * CFG.gyro_arw * np.sqrt(RATE)
    accel = f_b + rng.normal(size=3) * CFG.p0_accel_bias + rng.normal(size=(n, 3)) * CFG.accel_vrw * np.sqrt(RATE)
    tg = np.arange(1, int(seconds * GNSS_RATE) + 1) / GNSS_RATE
    ant = lla_to_ecef(*LLA) + Rotation.from_euler("zx", [LLA[1] + np.pi / 2, np.pi / 2 - LLA[0]]).apply(
        rot.apply(LEVER))
    pos = ant + rng.normal(size=(tg.size, 3)) * 0.5
    vel = rng.normal(size=(tg.size, 3)) * 0.05
    init = InitialState(0.0, LLA, np.zeros(3), rot.as_quat())
    return ImuData(t, gyro, accel), GnssFixes(tg, pos, vel, np.full(3, 0.5), np.full(3, 0.05), LEVER), init


def ours(imu, gnss, init):
    KalmanFilter15(CFG, init).run(ImuData(imu.t[:200], imu.gyro[:200], imu.accel[:200]), gnss, init=init)
    start = time.perf_counter()
    sol = KalmanFilter15(CFG, init).run(imu, gnss)
    return time.perf_counter() - start, sol


def pyins_run(imu, gnss, init, seconds):
    import pandas as pd
    from pyins import filters, inertial_sensor, measurements, strapdown

    from simkit.frames import SWAP, attitude_to_ned_frd, ecef_to_lla

    n = int(seconds * RATE) + 1
    raw = pd.DataFrame(np.hstack([imu.gyro[:n] @ SWAP.T, imu.accel[:n] @ SWAP.T]), index=imu.t[:n],
                       columns=["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"])
    rph = attitude_to_ned_frd(Rotation.from_quat(init.quat_nb)).as_euler("xyz", degrees=True)
    pva = pd.Series([np.degrees(LLA[0]), np.degrees(LLA[1]), LLA[2], 0.0, 0.0, 0.0, *rph], name=0.0,
                    index=["lat", "lon", "alt", "VN", "VE", "VD", "roll", "pitch", "heading"])
    m = gnss.t <= seconds
    lla = ecef_to_lla(gnss.pos_ecef[m])
    pos = pd.DataFrame(np.column_stack([np.degrees(lla[:, :2]), lla[:, 2]]), index=gnss.t[m],
                       columns=["lat", "lon", "alt"])
    vel = pd.DataFrame(gnss.vel_enu[m] @ SWAP.T, index=gnss.t[m], columns=["VN", "VE", "VD"])
    meas = [measurements.Position(pos, 0.5, SWAP @ LEVER), measurements.NedVelocity(vel, 0.05, SWAP @ LEVER)]
    gm = inertial_sensor.EstimationModel(bias_sd=CFG.p0_gyro_bias, noise=CFG.gyro_arw)
    am = inertial_sensor.EstimationModel(bias_sd=CFG.p0_accel_bias, noise=CFG.accel_vrw)
    start = time.perf_counter()
    increments = strapdown.compute_increments_from_imu(raw, "rate")
    filters.run_feedback_filter(pva, 2.0, 0.1, np.degrees(0.005), np.degrees(0.02), increments, gm, am, meas,
                                time_step=0.1)
    return time.perf_counter() - start, n


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=1.0)
    ap.add_argument("--pyins-seconds", type=float, default=60.0)
    a = ap.parse_args()
    imu, gnss, init = data(a.hours * 3600.0)
    wall, sol = ours(imu, gnss, init)
    n = imu.t.size
    print(f"simkit kf15: {n} IMU samples, {gnss.t.size} GNSS fixes in {wall:.2f} s = {n / wall:,.0f} samples/s "
          f"(target >= 100,000)")
    pw, pn = pyins_run(imu, gnss, init, a.pyins_seconds)
    print(f"pyins run_feedback_filter: {pn} IMU samples ({a.pyins_seconds:g} s of the same data) in {pw:.2f} s = "
          f"{pn / pw:,.0f} samples/s")
    print(f"ratio simkit / pyins (samples per second): {(n / wall) / (pn / pw):,.0f}x")


if __name__ == "__main__":
    main()
