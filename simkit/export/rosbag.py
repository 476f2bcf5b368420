"""``simkit export --format rosbag2``: a ROS 2 bag written with the pure-Python ``rosbags`` library (no ROS).

Topics (REP-103 axes, REP-105 frame names):

| topic | type | frame_id -> child | content |
|---|---|---|---|
| /imu/data | sensor_msgs/msg/Imu | imu_link | gyro and accel in FLU; orientation unknown (covariance[0] = -1) |
| /gnss/ant<k>/fix | sensor_msgs/msg/NavSatFix | gnss<k>_link | true phase centre of antenna k (+ white noise of ``fix_sigma_m``), ellipsoidal height |
| /solutions/<name>/fix | sensor_msgs/msg/NavSatFix | gnss<k>_link for a solution of antenna k, else base_link | each /solutions group with positions (SPP, filters): its epochs with a position, ENU covariance from its pos_e/pos_n/pos_u states when present |
| /ground_truth/odom | nav_msgs/msg/Odometry | map -> base_link | pose in map (ENU at the first truth sample), twist in base_link (FLU), relative to the Earth |
| /ground_truth/pose | geometry_msgs/msg/PoseStamped | map | the same pose |
| /tf | tf2_msgs/msg/TFMessage | map -> base_link | the same pose |
| /tf_static | tf2_msgs/msg/TFMessage | earth -> map, base_link -> imu_link, base_link -> gnss<k>_link | once, at the first stamp |

``earth`` is ECEF (REP-105); ``map`` is the ENU tangent frame at the first truth sample; ``base_link`` the IMU
centre with FLU axes (x forward = simkit body y, y left = -simkit body x, z up).
"""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from .. import frames
from ..atomic import temporary_name
from .streams import FileStreams, attitude, body_vectors, omega_eb_b, stamps_ns

TOPICS = {"imu": "/imu/data", "odom": "/ground_truth/odom", "pose": "/ground_truth/pose", "tf": "/tf",
          "tf_static": "/tf_static"}
MAP, BASE, IMU, EARTH = "map", "base_link", "imu_link", "earth"


def fix_topic(k: int) -> str:
    return f"/gnss/ant{k}/fix"


def _types():
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_HUMBLE)


def _map_frame(truth):
    """ECEF origin and C_e^map of the map frame (ENU at the first truth sample)."""
    lat, lon, _ = truth["pos_lla"][0]
    return truth["pos_ecef"][0], frames.ecef_to_enu_matrix(lat, lon)


def write(streams: FileStreams, out: Path, stamp: str = "unix", fix_sigma_m: float = 0.0, seed: int = 0) -> Path:
    """The bag folder ``out`` (written under a temporary name and renamed when complete)."""
    from rosbags.rosbag2 import Writer

    ts = _types()
    tmp = temporary_name(out)             # a hidden folder beside ``out``; the bag inside keeps out's name
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir()
    try:
        with Writer(tmp / out.name, version=8) as w:
            _fill(w, ts, streams, stamp, fix_sigma_m, seed)
        if out.exists():
            shutil.rmtree(out)
        (tmp / out.name).rename(out)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return out


def _header(ts, ns, frame_id):
    H, T = ts.types["std_msgs/msg/Header"], ts.types["builtin_interfaces/msg/Time"]
    return H(stamp=T(sec=int(ns // 10**9), nanosec=int(ns % 10**9)), frame_id=frame_id)


def _vec(ts, v):
    return ts.types["geometry_msgs/msg/Vector3"](x=float(v[0]), y=float(v[1]), z=float(v[2]))


def _quat(ts, q):
    return ts.types["geometry_msgs/msg/Quaternion"](x=float(q[0]), y=float(q[1]), z=float(q[2]), w=float(q[3]))


def _transform(ts, ns, parent, child, trans, quat):
    M = ts.types
    return M["geometry_msgs/msg/TransformStamped"](
        header=_header(ts, ns, parent), child_frame_id=child,
        transform=M["geometry_msgs/msg/Transform"](translation=_vec(ts, trans), rotation=_quat(ts, quat)))


def _fill(w, ts, s: FileStreams, stamp, fix_sigma_m, seed):
    M = ts.types
    conn = lambda topic, kind: w.add_connection(topic, kind, typestore=ts)
    put = lambda c, ns, msg, kind: w.write(c, int(ns), bytes(ts.serialize_cdr(msg, kind)))
    tr = s.truth
    t_ns = stamps_ns(s.start, tr["t"], stamp)
    r0, c_em = _map_frame(tr)
    pos_map = (tr["pos_ecef"] - r0) @ c_em.T
    lla = tr["pos_lla"]
    c_en = frames.ecef_to_enu_matrix(lla[:, 0], lla[:, 1])
    # attitude base_link (FLU) -> map: C_n^map C_flu^n, with C_n^map = C_e^map C_n^e
    c_mn = Rotation.from_matrix(np.einsum("ij,nkj->nik", c_em, c_en))
    q_map = (c_mn * attitude(tr["quat_nb"], "enu-flu")).as_quat()
    v_body = body_vectors(Rotation.from_quat(tr["quat_nb"]).inv().apply(tr["vel_enu"]), "enu-flu")
    w_body = body_vectors(omega_eb_b(tr), "enu-flu")
    kinds = {"imu": "sensor_msgs/msg/Imu", "odom": "nav_msgs/msg/Odometry", "pose": "geometry_msgs/msg/PoseStamped",
             "tf": "tf2_msgs/msg/TFMessage", "tf_static": "tf2_msgs/msg/TFMessage"}
    c = {k: conn(TOPICS[k], kinds[k]) for k in ("odom", "pose", "tf", "tf_static")}
    static = [_transform(ts, t_ns[0], EARTH, MAP, r0, Rotation.from_matrix(c_em.T).as_quat()),
              _transform(ts, t_ns[0], BASE, IMU, np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))]
    if s.lever_arm_b is not None:
        for k, lever in enumerate(s.lever_arm_b):
            static.append(_transform(ts, t_ns[0], BASE, f"gnss{k}_link", body_vectors(lever, "enu-flu"),
                                     np.array([0.0, 0.0, 0.0, 1.0])))
    put(c["tf_static"], t_ns[0], M["tf2_msgs/msg/TFMessage"](transforms=static), kinds["tf_static"])
    zero36 = np.zeros(36)
    Pose, PwC, TwC = M["geometry_msgs/msg/Pose"], M["geometry_msgs/msg/PoseWithCovariance"], M["geometry_msgs/msg/TwistWithCovariance"]
    Point, Twist = M["geometry_msgs/msg/Point"], M["geometry_msgs/msg/Twist"]
    for i in range(len(t_ns)):
        pose = Pose(position=Point(x=float(pos_map[i, 0]), y=float(pos_map[i, 1]), z=float(pos_map[i, 2])),
                    orientation=_quat(ts, q_map[i]))
        put(c["pose"], t_ns[i], M["geometry_msgs/msg/PoseStamped"](header=_header(ts, t_ns[i], MAP), pose=pose),
            kinds["pose"])
        odom = M["nav_msgs/msg/Odometry"](header=_header(ts, t_ns[i], MAP), child_frame_id=BASE,
                                          pose=PwC(pose=pose, covariance=zero36),
                                          twist=TwC(twist=Twist(linear=_vec(ts, v_body[i]), angular=_vec(ts, w_body[i])),
                                                    covariance=zero36))
        put(c["odom"], t_ns[i], odom, kinds["odom"])
        put(c["tf"], t_ns[i], M["tf2_msgs/msg/TFMessage"](
            transforms=[_transform(ts, t_ns[i], MAP, BASE, pos_map[i], q_map[i])]), kinds["tf"])
    if s.imu_t is not None:
        ci = conn(TOPICS["imu"], kinds["imu"])
        i_ns = stamps_ns(s.start, s.imu_t, stamp)
        gyro, accel = body_vectors(s.gyro, "enu-flu"), body_vectors(s.accel, "enu-flu")
        unknown = np.zeros(9)
        unknown[0] = -1.0
        for i in range(len(i_ns)):
            msg = M["sensor_msgs/msg/Imu"](header=_header(ts, i_ns[i], IMU), orientation=_quat(ts, [0, 0, 0, 1]),
                                           orientation_covariance=unknown, angular_velocity=_vec(ts, gyro[i]),
                                           angular_velocity_covariance=np.zeros(9),
                                           linear_acceleration=_vec(ts, accel[i]),
                                           linear_acceleration_covariance=np.zeros(9))
            put(ci, i_ns[i], msg, kinds["imu"])
    if s.antenna_ecef is not None:
        _fixes(w, ts, s, stamp, fix_sigma_m, seed, conn, put)
    for name, sol in s.solutions.items():
        if sol.pos_ecef is not None:
            _solution_fixes(ts, s.start, name, sol, stamp, conn, put)


def solution_topic(name: str) -> str:
    return f"/solutions/{name}/fix"


def _solution_fixes(ts, start, name, sol, stamp, conn, put):
    M = ts.types
    Fix, status = M["sensor_msgs/msg/NavSatFix"], M["sensor_msgs/msg/NavSatStatus"]
    ok = np.isfinite(sol.pos_ecef).all(axis=1)
    t_ns = stamps_ns(start, sol.t[ok], stamp)
    lla = frames.ecef_to_lla(sol.pos_ecef[ok])
    names = list(sol.state_names)
    cov = None
    if sol.cov is not None and all(f"pos_{a}" in names for a in "enu"):
        idx = [names.index(f"pos_{a}") for a in "enu"]
        cov = sol.cov[ok][:, idx][:, :, idx].reshape(-1, 9)
    frame = f"gnss{sol.point.split(':')[1]}_link" if sol.point.startswith("antenna:") else BASE
    ck = conn(solution_topic(name), "sensor_msgs/msg/NavSatFix")
    for i in range(len(t_ns)):
        msg = Fix(header=_header(ts, t_ns[i], frame),
                  status=status(status=status.STATUS_FIX, service=status.SERVICE_GPS | status.SERVICE_COMPASS),
                  latitude=float(np.degrees(lla[i, 0])), longitude=float(np.degrees(lla[i, 1])),
                  altitude=float(lla[i, 2]), position_covariance=np.zeros(9) if cov is None else cov[i],
                  position_covariance_type=Fix.COVARIANCE_TYPE_UNKNOWN if cov is None else Fix.COVARIANCE_TYPE_KNOWN)
        put(ck, t_ns[i], msg, "sensor_msgs/msg/NavSatFix")


def _fixes(w, ts, s, stamp, sigma, seed, conn, put):
    M = ts.types
    g_ns = stamps_ns(s.start, s.gnss_t, stamp)
    rng = np.random.default_rng(seed)
    status = M["sensor_msgs/msg/NavSatStatus"]
    cov = np.diag([sigma**2] * 3).ravel()
    cov_type = M["sensor_msgs/msg/NavSatFix"].COVARIANCE_TYPE_DIAGONAL_KNOWN
    for k in range(s.antenna_ecef.shape[1]):
        ck = conn(fix_topic(k), "sensor_msgs/msg/NavSatFix")
        pos = s.antenna_ecef[:, k]
        lla = frames.ecef_to_lla(pos)
        if sigma > 0:
            noise = rng.normal(0.0, sigma, pos.shape)
            pos = pos + frames.enu_to_ecef_vec(noise, lla[:, 0], lla[:, 1])
            lla = frames.ecef_to_lla(pos)
        for i in range(len(g_ns)):
            msg = M["sensor_msgs/msg/NavSatFix"](
                header=_header(ts, g_ns[i], f"gnss{k}_link"),
                status=status(status=status.STATUS_FIX, service=status.SERVICE_GPS | status.SERVICE_COMPASS),
                latitude=float(np.degrees(lla[i, 0])), longitude=float(np.degrees(lla[i, 1])), altitude=float(lla[i, 2]),
                position_covariance=cov, position_covariance_type=cov_type)
            put(ck, g_ns[i], msg, "sensor_msgs/msg/NavSatFix")
