"""The streams an exporter writes, read once from a simkit file, and the conversions at the edge.

simkit inside: ENU navigation frame, body x right / y forward / z up (RFU), attitude body->ENU. Outside:
- ROS (REP-103): ENU world, body FLU: x forward = simkit y, y left = -simkit x, z up; the FLU attitude is the
  RFU one times a +90 deg turn about z (C_flu^enu = C_rfu^enu R_z(90 deg));
- aerospace: NED, body FRD (:data:`simkit.frames.SWAP` on both sides; the referee's converter).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from .. import frames, gpstime
from ..earth import EARTH_RATE_ECEF
from ..errors import DataFileError

RFU_TO_FLU = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])   # v_flu = RFU_TO_FLU @ v_rfu
_FLU_IN_RFU = Rotation.from_matrix(RFU_TO_FLU.T)                              # C_flu^rfu


@dataclass(frozen=True)
class FileStreams:
    """What the exporters need of one file: GPS ``start`` (week, sow); truth (``t`` (N,) s, ``pos_ecef``,
    ``pos_lla``, ``vel_enu``, ``quat_nb``, ``euler``, ``omega_ib_b``, ``f_ib_b``); IMU ``imu_t``, ``gyro``,
    ``accel`` (None without /imu); antennas ``gnss_t`` (M,), ``lever_arm_b`` (A, 3), ``antenna_ecef`` (M, A, 3)
    (None without /gnss); ``solutions`` {name: Solution}."""

    name: str
    start: tuple[int, float]
    truth: dict
    imu_t: np.ndarray | None = None
    gyro: np.ndarray | None = None
    accel: np.ndarray | None = None
    gnss_t: np.ndarray | None = None
    lever_arm_b: np.ndarray | None = None
    antenna_ecef: np.ndarray | None = None
    solutions: dict = field(default_factory=dict)


def read_streams(path) -> FileStreams:
    from ..io import open_dataset, read_imu, read_solution, read_truth, solution_names

    fields = ("pos_ecef", "pos_lla", "vel_enu", "quat_nb", "euler", "omega_ib_b", "f_ib_b")
    with open_dataset(path) as ds:
        if "truth/t" not in ds:
            raise DataFileError(path, "no /truth group: export needs a simulated file")
        start = (int(ds.attrs["start_gps_week"]), float(ds.attrs["start_gps_sow"]))
        tr = read_truth(ds, fields=fields, required=fields)
        truth = {"t": tr.t, **{k: getattr(tr, k) for k in fields}}
        imu = read_imu(ds, fields=("gyro", "accel")) if "imu/t" in ds else None
        gnss_t = lever = ant = None
        if "gnss/t" in ds:
            gnss_t = ds["gnss/t"][:]
            lever = ds["gnss/antennas/lever_arm_b"][:]
            at = read_truth(ds, t=gnss_t, fields=fields, required=fields, tol_s=1e-6)
            vel_e = frames.enu_to_ecef_vec(at.vel_enu, at.pos_lla[:, 0], at.pos_lla[:, 1])
            ant = frames.lever_arm_ecef(at.pos_ecef, vel_e, at.quat_nb, at.omega_ib_b, lever)[0]
        name = ds.scenario_name
    sols = {n: read_solution(path, n) for n in solution_names(path)}
    return FileStreams(name, start, truth, None if imu is None else imu.t, None if imu is None else imu.gyro,
                       None if imu is None else imu.accel, gnss_t, lever, ant, sols)


def body_vectors(v_rfu, frame: str) -> np.ndarray:
    """Body-frame vectors (..., 3) from simkit's RFU axes into ``frame``'s body axes (FRD, RFU or FLU)."""
    v = np.asarray(v_rfu, dtype=float)
    if frame == "ned-frd":
        return frames.enu_to_ned(v)
    if frame == "enu-flu":
        return v @ RFU_TO_FLU.T
    return v


def nav_vectors(v_enu, frame: str) -> np.ndarray:
    """Navigation-frame vectors (..., 3) from ENU into ``frame``'s navigation axes (NED or ENU)."""
    return frames.enu_to_ned(v_enu) if frame == "ned-frd" else np.asarray(v_enu, dtype=float)


def attitude(quat_nb, frame: str) -> Rotation:
    """simkit body(RFU)->ENU quaternions as the body->navigation rotation of ``frame``."""
    rot = Rotation.from_quat(quat_nb)
    if frame == "ned-frd":
        return frames.attitude_to_ned_frd(rot)
    if frame == "enu-flu":
        return rot * _FLU_IN_RFU
    return rot


def omega_eb_b(truth: dict) -> np.ndarray:
    """Body rate relative to the Earth, w_eb^b = w_ib^b - C_e^b w_ie^e (N, 3) rad/s, simkit body axes."""
    lla = truth["pos_lla"]
    c_en = frames.ecef_to_enu_matrix(lla[:, 0], lla[:, 1])
    w_ie_n = np.einsum("nij,j->ni", c_en, EARTH_RATE_ECEF)
    return truth["omega_ib_b"] - Rotation.from_quat(truth["quat_nb"]).inv().apply(w_ie_n)



def stamps_ns(start: tuple[int, float], t, stamp: str) -> np.ndarray:
    """Integer nanosecond stamps of times ``t`` (s since the scenario start): ``unix`` UTC seconds since 1970
    (the leap seconds of the start, as ROS time), ``gps`` GPS seconds since 1980-01-06, ``start`` since the
    scenario start."""
    t_ns = np.round(np.asarray(t, dtype=float) * 1e9).astype(np.int64)
    week, sow = start
    whole = int(np.floor(sow))
    frac_ns = int(round((sow - whole) * 1e9))
    if stamp == "start":
        base = 0
    elif stamp == "gps":
        base = (week * 604800 + whole) * 10**9 + frac_ns
    else:
        utc = gpstime.gps_to_utc(week, float(whole))
        base = int(utc.timestamp()) * 10**9 + frac_ns
    return base + t_ns
