"""Side-by-side with a peer: the same simkit file through pyins' feedback filter (PyPI ``python-ins``, NED /
forward-right-down conventions, degrees) and through simkit's kf15, with the same initial state, the same
GNSS position/velocity fixes (truth plus white noise, one sigma for all axes as pyins takes it), the same lever
arm and the same IMU noise model. pyins is a bench/test extra, imported only here."""
from __future__ import annotations

import time

import numpy as np
from scipy.spatial.transform import Rotation

from simkit.frames import (SWAP, attitude_from_ned_frd, attitude_to_ned_frd, ecef_to_lla, euler_from_attitude,
                      lla_to_ecef)
from simkit.io import open_dataset
from simkit.solution import Solution
from simkit.estimators.registry import SOLVERS, filter_config, gnss_fixes, imu_data, initial_state, merged
from studies.evaluate import rms_table

PARAMS = {"gnss": "truth", "truth_pos_sigma_m": [1.0, 1.0, 1.0], "truth_vel_sigma_m_per_s": 0.05,
          "align": "truth", "init_heading_error_deg": 2.0, "p0_att_deg": [1.0, 1.0, 3.0], "p0_pos_m": [2.0, 2.0, 2.0],
          "p0_vel_m_per_s": 0.5}


def _frame(index, data, columns):
    import pandas as pd

    return pd.DataFrame(np.asarray(data), index=pd.Index(np.asarray(index, float)), columns=columns)


def pyins_inputs(ds, p):
    """pyins' increments, initial PVA, measurements and sensor models built from the simkit file."""
    import pandas as pd
    from pyins import inertial_sensor, measurements, strapdown

    imu, gnss = imu_data(ds), gnss_fixes(ds, p)
    init = initial_state(ds, p, imu, gnss)
    cfg = filter_config(ds, p, "kf15")
    raw = _frame(imu.t, np.hstack([imu.gyro @ SWAP.T, imu.accel @ SWAP.T]),
                 ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"])
    increments = strapdown.compute_increments_from_imu(raw, "rate")
    rph = attitude_to_ned_frd(Rotation.from_quat(init.quat_nb)).as_euler("xyz", degrees=True)
    lat, lon, h = init.pos_lla
    ve, vn, vu = init.vel_enu
    pva = pd.Series([np.degrees(lat), np.degrees(lon), h, vn, ve, -vu, *rph],
                    index=["lat", "lon", "alt", "VN", "VE", "VD", "roll", "pitch", "heading"], name=float(imu.t[0]))
    lla = ecef_to_lla(gnss.pos_ecef)
    lever = SWAP @ gnss.lever_arm_b
    pos = _frame(gnss.t, np.column_stack([np.degrees(lla[:, 0]), np.degrees(lla[:, 1]), lla[:, 2]]),
                 ["lat", "lon", "alt"])
    vel = _frame(gnss.t, gnss.vel_enu @ SWAP.T, ["VN", "VE", "VD"])
    meas = [measurements.Position(pos, p["truth_pos_sigma_m"][0], lever),
            measurements.NedVelocity(vel, p["truth_vel_sigma_m_per_s"], lever)]
    models = (inertial_sensor.EstimationModel(bias_sd=cfg.p0_gyro_bias, noise=cfg.gyro_arw),
              inertial_sensor.EstimationModel(bias_sd=cfg.p0_accel_bias, noise=cfg.accel_vrw))
    sd = (p["p0_pos_m"][0], p["p0_vel_m_per_s"], p["p0_att_deg"][0], p["p0_att_deg"][2])
    return pva, sd, increments, models, meas, gnss.t


def run_pyins(ds, p) -> tuple[Solution, float]:
    """pyins' feedback filter on the file; the solution at the GNSS epochs, and the wall time of the filter."""
    from pyins import filters

    pva, sd, increments, (gm, am), meas, t_gnss = pyins_inputs(ds, p)
    start = time.perf_counter()
    res = filters.run_feedback_filter(pva, *sd, increments, gm, am, meas, time_step=0.1)
    wall = time.perf_counter() - start
    traj = res.trajectory
    t = np.asarray(traj.index, float)
    k = np.searchsorted(t, t_gnss[(t_gnss > t[0]) & (t_gnss <= t[-1])])
    tr = traj.iloc[k]
    lat, lon = np.radians(tr["lat"].to_numpy()), np.radians(tr["lon"].to_numpy())
    rot = attitude_from_ned_frd(Rotation.from_euler("xyz", tr[["roll", "pitch", "heading"]].to_numpy(), degrees=True))
    sol = Solution(t=t[k], pos_ecef=lla_to_ecef(lat, lon, tr["alt"].to_numpy()),
                   vel_enu=tr[["VN", "VE", "VD"]].to_numpy() @ SWAP.T, quat_nb=rot.as_quat(),
                   euler=euler_from_attitude(rot))
    return sol, wall


def compare_pyins(path, skip_s=60.0) -> dict:
    """RMS errors per axis (position ENU m, velocity ENU m/s, pitch/roll/heading deg) of both filters."""
    cols = ["pos_E_m", "pos_N_m", "pos_U_m", "vel_E_m_per_s", "vel_N_m_per_s", "vel_U_m_per_s", "pitch_deg",
            "roll_deg", "heading_deg"]
    with open_dataset(path) as ds:
        p = merged("kf15", PARAMS)
        start = time.perf_counter()
        ours = SOLVERS["kf15"](ds, p, False)
        wall_ours = time.perf_counter() - start
        theirs, wall_theirs = run_pyins(ds, p)
        n = ds["imu/t"].shape[0]
        out = {"simkit_kf15": dict(zip(cols, rms_table(ds, ours, skip_s).round(5).tolist())),
               "pyins": dict(zip(cols, rms_table(ds, theirs, skip_s).round(5).tolist()))}
    out["wall_s"] = {"simkit_kf15 (incl. reading)": round(wall_ours, 2), "pyins filter": round(wall_theirs, 2)}
    out["imu_samples"] = int(n)
    return out
