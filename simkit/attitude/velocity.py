"""``simkit solve --filter tdcp``: TDCP antenna velocity (:mod:`.tdcp`) and the IMU-centre velocity through the
lever arm (:mod:`.lever`), with covariances. The attitude for the lever arm comes from the multi-antenna solver
(``lever_attitude = "attitude"``: its fixed epochs), the file's truth (``"truth"``), or nothing (``"none"``);
``"auto"`` takes the solver with 3+ antennas, else none. The rate of the lever arm's turn comes from the
attitude at both ends of the interval (``lever_rate = "attitude"``) or from the IMU gyro mean over the interval
(``"imu"``, its white noise, turn-on bias and bias instability from /imu's model in the covariance).
"""
from __future__ import annotations

import json

import numpy as np
from scipy.spatial.transform import Rotation

from ..frames import ecef_to_enu_matrix, ecef_to_lla, euler_jacobian
from ..gnss.atmosphere import troposphere
from ..io import has, path_of, read_imu, read_truth
from ..solution import Solution, warn_truth
from .errors import AttitudeInputError
from .lever import lever_velocity_differenced, lever_velocity_rate, tdcp_velocity_covariance
from .params import TDCP_DEFAULTS, merge
from .reading import read
from .solvers import solver
from .tdcp import tdcp_velocity

_READ = {"pll_bandwidth_hz": 15.0, "dll_bandwidth_hz": 1.0, "correlator_spacing_chips": 0.5,
         "integration_time_s": 0.02, "carrier_multipath_m": 0.0, "code_multipath_m": 0.0,
         "multipath_elevation_deg": 20.0}


def _attitudes(ds, fd, p, source):
    """(R (M, 3, 3) body -> ENU, NaN where none; P (M, 3, 3) ENU attitude-error covariance rad^2)."""
    m = len(fd.t)
    if source == "truth":
        quat = read_truth(ds, t=fd.t, fields=("quat_nb",), required=("quat_nb",), tol_s=1e-9).quat_nb
        return Rotation.from_quat(quat).as_matrix(), np.zeros((m, 3, 3))
    sol = solver("attitude")(ds, {"start_s": p["start_s"], "stop_s": p["stop_s"], "every": p["every"],
                                  "signals": p["signals"], "mask_deg": p["mask_deg"]}, False)
    ok = np.isin(sol.extras["status"], (1, 3)) & np.isfinite(sol.quat_nb).all(1)
    R = np.full((m, 3, 3), np.nan)
    P = np.full((m, 3, 3), np.nan)
    if ok.any():
        R[ok] = Rotation.from_quat(sol.quat_nb[ok]).as_matrix()
        Ji = np.linalg.inv(euler_jacobian(Rotation.from_matrix(R[ok])))
        P[ok] = Ji @ sol.cov[ok] @ np.swapaxes(Ji, 1, 2)
    return R, P


def _gyro_mean(ds, t0, t1):
    """Mean w_ib^b (K, 3) rad/s over (t0, t1] from /imu, and the rate error covariance (K, 3, 3)."""
    if not has(ds, "imu", "gyro") and not has(ds, "imu", "dtheta"):
        raise AttitudeInputError(path_of("imu", "gyro"), "missing; estimator.lever_rate = 'imu' needs IMU data")
    imu = read_imu(ds, fields=("gyro",) if has(ds, "imu", "gyro") else ("dtheta",))
    t = imu.t
    inc = imu.gyro * np.gradient(t)[:, None] if imu.gyro is not None else imu.dtheta
    c = np.concatenate([np.zeros((1, 3)), np.cumsum(inc, axis=0)])
    i0, i1 = np.searchsorted(t, t0 + 1e-9), np.searchsorted(t, t1 + 1e-9)
    dt = t1 - t0
    w = (c[i1] - c[i0]) / dt[:, None]
    g = json.loads(ds.group_attrs("imu").get("gyro", "{}"))
    var = g.get("random_walk", 0.0) ** 2 / dt + (g.get("bias_turn_on", 0.0) + g.get("bias_instability", 0.0)) ** 2
    return w, var[:, None, None] * np.eye(3)


def imu_centre_velocity(ds, fd, p, vel_enu, lla):
    """(v_imu (K, 3), its lever-arm covariance (K, 3, 3), attitude source used) for the K intervals of ``fd``."""
    n_ant = fd.lever_arm.shape[0]
    source = p["lever_attitude"]
    if source == "auto":
        source = "attitude" if n_ant >= 3 else "none"
    K = len(vel_enu)
    if source == "none":
        return np.full((K, 3), np.nan), np.full((K, 3, 3), np.nan), source
    if source == "attitude" and n_ant < 3:
        raise AttitudeInputError("estimator.lever_attitude", f"'attitude' needs 3 or more antennas, found {n_ant}")
    R, P = _attitudes(ds, fd, p, source)
    lever = fd.lever_arm[p["antenna"]]
    E = ecef_to_enu_matrix(lla[:, 0], lla[:, 1])
    if p["lever_rate"] == "attitude":
        v, cov = lever_velocity_differenced(R[:-1], R[1:], E[:-1], E[1:], lever, np.diff(fd.t), P[:-1], P[1:])
    else:
        w, cov_w = _gyro_mean(ds, fd.t[:-1], fd.t[1:])
        Rm, Pm = _midpoint(R, P)
        v, cov = lever_velocity_rate(Rm, w, lla[:-1, 0], lever, Pm, cov_w)
    return vel_enu - v, cov, source


def _midpoint(R, P):
    """Attitude (K, 3, 3) at the middle of each interval (slerp; the one end that has it otherwise) and the larger
    end covariance."""
    ok = np.isfinite(R).all((1, 2))
    Rm = np.where(ok[:-1, None, None], R[:-1], R[1:])
    both = np.flatnonzero(ok[:-1] & ok[1:])
    if both.size:
        r0 = Rotation.from_matrix(R[both])
        r1 = Rotation.from_matrix(R[both + 1])
        half = Rotation.from_rotvec(0.5 * (r1 * r0.inv()).as_rotvec())
        Rm[both] = (half * r0).as_matrix()
    Pm = np.where(np.isfinite(P[:-1]), P[:-1], P[1:])
    return Rm, Pm


def solve_tdcp(ds, params: dict | None = None, progress: bool = False) -> Solution:
    """TDCP velocity of antenna ``antenna`` and of the IMU centre (see docs/attitude.md)."""
    p = merge(TDCP_DEFAULTS, params, "tdcp")
    fd = read(ds, {**p, **_READ})
    g, m, a, s = fd.obs.carrier.shape
    ant = p["antenna"]
    if not 0 <= ant < a:
        raise AttitudeInputError("estimator.antenna", f"{ant}; expected 0 .. {a - 1}")
    if m < 2:
        raise AttitudeInputError(path_of("gnss", "t"), f"{m} epoch(s); TDCP needs at least 2")
    phase = (fd.obs.carrier[:, :, ant] * fd.obs.wavelength[:, None, None]).transpose(1, 0, 2).reshape(m, -1)
    up = fd.obs.elevation >= np.radians(p["mask_deg"])
    ok = np.isfinite(phase) & np.tile(up, (1, g))
    lli = (fd.lli[:, :, ant] > 0).transpose(1, 0, 2).reshape(m, -1)
    usable = ok[1:] & ok[:-1] & ~lli[1:]
    sat_pos, sat_clock = np.tile(fd.sat_pos, (1, g, 1)), np.tile(fd.sat_clock, (1, g))
    dt = np.diff(fd.t)
    lla = ecef_to_lla(fd.receiver)
    tropo = troposphere(lla[:, 0:1], lla[:, 2:3], np.tile(np.maximum(fd.obs.elevation, 0.05), (1, g)))
    vel, drift, used, rms = tdcp_velocity(phase, usable, sat_pos, sat_clock, fd.receiver, dt, p["carrier_sigma_m"],
                                          p["slip_threshold"], delay_m=tropo if p["troposphere"] else None)
    vel_enu = np.einsum("kij,kj->ki", ecef_to_enu_matrix(lla[:-1, 0], lla[:-1, 1]), vel)
    cov_ant = tdcp_velocity_covariance(np.tile(fd.obs.los[:-1], (1, g, 1)), used, p["carrier_sigma_m"], dt)
    v_imu, cov_lever, source = imu_centre_velocity(ds, fd, p, vel_enu, lla)
    extras = {"vel_enu_antenna": vel_enu, "vel_enu_antenna_cov": cov_ant, "vel_enu_imu": v_imu,
              "vel_enu_imu_cov": cov_ant + cov_lever, "clock_drift": drift, "n_used": used.sum(1).astype(np.int16),
              "n_rejected": (usable & ~used).sum(1).astype(np.int16), "residual_rms": rms}
    units = {"vel_enu_antenna": "m/s", "vel_enu_antenna_cov": "(m/s)^2", "vel_enu_imu": "m/s (IMU centre)",
             "vel_enu_imu_cov": "(m/s)^2", "clock_drift": "m/s", "n_used": "1", "n_rejected": "1",
             "residual_rms": "m"}
    truth = ["lever_attitude"] if source == "truth" else []
    warn_truth("tdcp", truth, {"lever_attitude": "the true attitude for the lever arm"})
    config = {"estimator": "tdcp", **p, "signals": list(fd.signals), "lever_attitude_used": source,
              "truth_inputs": truth}
    config["stop_s"] = None if np.isinf(p["stop_s"]) else p["stop_s"]
    return Solution(t=0.5 * (fd.t[1:] + fd.t[:-1]), extras=extras, extra_units=units, config=config,
                    vel_enu=vel_enu, cov=cov_ant, state_names=("vel_e", "vel_n", "vel_u"), point=f"antenna:{ant}")
