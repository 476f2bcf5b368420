"""``simkit export``: a ROS 2 bag of airborne_stim300 read back with the rosbags reader (message counts, stamps
and values equal the file's, frames converted as REP-103 says, checked through pymap3d), CSV streams whose
NED/FRD solution is scored by ``simkit score`` exactly as the /solutions group is, and KML tracks read back."""
import numpy as np
import pymap3d
import pytest
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore
from scipy.spatial.transform import Rotation

from cli_errors import assert_clean_error, run_cli
from simkit import frames, gpstime, run
from simkit.api import export, score
from simkit.io import open_dataset, read_imu, read_truth, write_solution
from simkit.logs import read
from simkit.solution import Solution

DURATION = 20.0


@pytest.fixture(scope="module")
def h5(tmp_path_factory):
    folder = tmp_path_factory.mktemp("export")
    path = run("airborne_stim300", out=folder / "air.h5", overrides={"scenario.duration_s": DURATION})
    with open_dataset(path) as ds:
        tr = read_truth(ds, fields=("pos_ecef", "vel_enu", "quat_nb", "euler"))
    rng = np.random.default_rng(1)
    k = slice(None, None, 10)
    quat = (Rotation.from_rotvec(rng.normal(0, 0.01, (len(tr.t[k]), 3))) * Rotation.from_quat(tr.quat_nb[k])).as_quat()
    write_solution(path, "pert", Solution(t=tr.t[k], pos_ecef=tr.pos_ecef[k] + rng.normal(0, 1.0, (len(tr.t[k]), 3)),
                                          vel_enu=tr.vel_enu[k] + rng.normal(0, 0.1, (len(tr.t[k]), 3)),
                                          quat_nb=quat, euler=frames.euler_from_attitude(Rotation.from_quat(quat))))
    return path


@pytest.fixture(scope="module")
def bag(h5):
    out = h5.parent / "bag"
    export(h5, "rosbag2", out, stamp="unix")
    ts = get_typestore(Stores.ROS2_HUMBLE)
    msgs = {}
    with Reader(out) as r:
        for conn, stamp, raw in r.messages():
            msgs.setdefault(conn.topic, []).append((stamp, ts.deserialize_cdr(raw, conn.msgtype)))
    return msgs


def _file(h5):
    with open_dataset(h5) as ds:
        tr = read_truth(ds, fields=("pos_ecef", "pos_lla", "vel_enu", "quat_nb", "omega_ib_b"))
        imu = read_imu(ds, fields=("gyro", "accel"))
        gnss_t = ds["gnss/t"][:]
        start = (int(ds.attrs["start_gps_week"]), float(ds.attrs["start_gps_sow"]))
    return tr, imu, gnss_t, start


def _unix_ns(start, t):
    utc = gpstime.gps_to_utc(*start)
    return int(round(utc.timestamp())) * 10**9 + np.round(np.asarray(t) * 1e9).astype(np.int64)


def test_bag_counts_and_stamps_equal_the_file(h5, bag):
    tr, imu, gnss_t, start = _file(h5)
    n, m = len(tr.t), len(gnss_t)
    counts = {k: len(v) for k, v in bag.items()}
    assert counts == {"/tf_static": 1, "/ground_truth/pose": n, "/ground_truth/odom": n, "/tf": n, "/imu/data": len(imu.t),
                      **{f"/gnss/ant{k}/fix": m for k in range(tr.lever_arm_b.shape[0])},
                      "/solutions/pert/fix": len(tr.t[::10])}
    for topic, t in (("/imu/data", imu.t), ("/ground_truth/odom", tr.t), ("/gnss/ant1/fix", gnss_t)):
        stamps = np.array([s for s, _ in bag[topic]])
        headers = np.array([msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec for _, msg in bag[topic]])
        assert np.array_equal(stamps, _unix_ns(start, t)) and np.array_equal(headers, stamps)


def test_bag_imu_is_the_file_imu_in_flu(h5, bag):
    _, imu, _, _ = _file(h5)
    gyro = np.array([[m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z] for _, m in bag["/imu/data"]])
    accel = np.array([[m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z]
                      for _, m in bag["/imu/data"]])
    flu = lambda v: np.stack([v[:, 1], -v[:, 0], v[:, 2]], -1)    # x forward = y, y left = -x, z up
    assert np.array_equal(gyro, flu(imu.gyro)) and np.array_equal(accel, flu(imu.accel))
    assert all(m.orientation_covariance[0] == -1.0 and m.header.frame_id == "imu_link" for _, m in bag["/imu/data"])


def test_bag_pose_and_fixes_through_pymap3d(h5, bag):
    tr, _, _, _ = _file(h5)
    lat0, lon0, h0 = np.degrees(tr.pos_lla[0, 0]), np.degrees(tr.pos_lla[0, 1]), tr.pos_lla[0, 2]
    pos = np.array([[m.pose.position.x, m.pose.position.y, m.pose.position.z] for _, m in bag["/ground_truth/pose"]])
    ref = np.stack(pymap3d.ecef2enu(*tr.pos_ecef.T, lat0, lon0, h0), -1)
    assert pos == pytest.approx(ref, abs=1e-6)
    # the FLU x axis (forward) of base_link in map axes is simkit's body y, carried ENU -> ECEF -> map ENU
    q = np.array([[m.pose.orientation.x, m.pose.orientation.y, m.pose.orientation.z, m.pose.orientation.w]
                  for _, m in bag["/ground_truth/pose"]])
    fwd_enu = Rotation.from_quat(tr.quat_nb).apply([0.0, 1.0, 0.0])
    uvw = np.stack(pymap3d.enu2uvw(*fwd_enu.T, np.degrees(tr.pos_lla[:, 0]), np.degrees(tr.pos_lla[:, 1])), -1)
    fwd_map = np.stack(pymap3d.uvw2enu(*uvw.T, lat0, lon0), -1)
    assert Rotation.from_quat(q).apply([1.0, 0.0, 0.0]) == pytest.approx(fwd_map, abs=1e-9)
    odom = bag["/ground_truth/odom"]
    assert {(m.header.frame_id, m.child_frame_id) for _, m in odom} == {("map", "base_link")}
    speed = np.array([np.linalg.norm([m.twist.twist.linear.x, m.twist.twist.linear.y, m.twist.twist.linear.z])
                      for _, m in odom])
    assert speed == pytest.approx(np.linalg.norm(tr.vel_enu, axis=1), abs=1e-9)
    # antenna k: the IMU centre plus the lever arm rotated body -> ENU -> ECEF
    with open_dataset(h5) as ds:
        at = read_truth(ds, t=ds["gnss/t"][:], fields=("pos_ecef", "pos_lla", "quat_nb"))
    for k, lever in enumerate(at.lever_arm_b):
        l_enu = Rotation.from_quat(at.quat_nb).apply(lever)
        ant = at.pos_ecef + np.stack(pymap3d.enu2uvw(*l_enu.T, np.degrees(at.pos_lla[:, 0]),
                                                    np.degrees(at.pos_lla[:, 1])), -1)
        lat, lon, h = pymap3d.ecef2geodetic(*ant.T)
        fix = np.array([[m.latitude, m.longitude, m.altitude] for _, m in bag[f"/gnss/ant{k}/fix"]])
        assert fix[:, :2] == pytest.approx(np.stack([lat, lon], -1), abs=1e-10)
        assert fix[:, 2] == pytest.approx(h, abs=1e-5)
    sol = np.array([[m.latitude, m.longitude, m.altitude] for _, m in bag["/solutions/pert/fix"]])
    with open_dataset(h5) as ds:
        pert = ds["solutions/pert/pos_ecef"][:]
    ref = np.stack(pymap3d.ecef2geodetic(*pert.T), -1)
    assert sol[:, :2] == pytest.approx(ref[:, :2], abs=1e-10) and sol[:, 2] == pytest.approx(ref[:, 2], abs=1e-5)
    static = {(t.header.frame_id, t.child_frame_id): t.transform for t in bag["/tf_static"][0][1].transforms}
    g1 = static[("base_link", "gnss1_link")].translation
    lever = at.lever_arm_b[1]
    assert [g1.x, g1.y, g1.z] == [lever[1], -lever[0], lever[2]]
    assert ("earth", "map") in static and ("base_link", "imu_link") in static


def test_csv_in_ned_frd_scores_as_the_hdf5(h5, tmp_path):
    paths = export(h5, "csv", tmp_path / "csv", frame="ned-frd")
    assert {p.name for p in paths} >= {"truth.csv", "imu.csv", "antenna_0.csv", "solution_pert.csv"}
    a = score(h5, h5, solution="pert")
    b = score(h5, tmp_path / "csv" / "solution_pert.csv")
    for key, stats in a.statistics.items():
        for stat, value in stats.items():
            # positions pass through geodetic degrees: pymap3d's ECEF <-> geodetic round trip is good to ~2e-9 m
            assert b.statistics[key][stat] == pytest.approx(value, rel=1e-9, abs=1e-8), (key, stat)
    print(f"\nscore of the NED/FRD CSV = score of /solutions/pert: horizontal RMS "
          f"{a.statistics['horizontal']['rms']:.4f} m, heading RMS {a.statistics['heading']['rms']:.4f} deg")
    lines = (tmp_path / "csv" / "imu.csv").read_text().splitlines()
    assert lines[0].startswith("# simkit export") and "convention ned-frd" in lines[0]
    cols = np.loadtxt(lines[2:], delimiter=",", ndmin=2)
    imu_csv = {name: cols[:, j] for j, name in enumerate(lines[1].split(","))}
    _, imu, _, _ = _file(h5)
    frd = lambda v: np.stack([v[:, 1], v[:, 0], -v[:, 2]], -1)    # x forward = y, y right = x, z down = -z
    got = np.stack([imu_csv[f"gyro_{a}_rad_per_s"] for a in "xyz"], -1)
    assert np.array_equal(got, frd(imu.gyro))
    # truth.csv read back as a log: the file's epochs, positions and NED velocity to the written precision
    rec = read(tmp_path / "csv" / "truth.csv")
    tr, _, _, start = _file(h5)
    assert np.abs(gpstime.diff_seconds(rec.week, rec.sow, *start) - tr.t).max() < 1e-9   # sow ~1e5 s: 1.5e-11 s ulp
    assert np.abs(rec.pos_ecef - tr.pos_ecef).max() < 1e-8
    assert np.array_equal(rec.vel_enu, tr.vel_enu)


def test_kml_tracks_read_back(h5, tmp_path):
    out = tmp_path / "air.kml"
    export(h5, "kml", out, rate_hz=1.0)
    rec = read(out)
    tr, _, _, start = _file(h5)
    t = gpstime.diff_seconds(rec.week, rec.sow, *start)
    n = int(DURATION) + 1
    assert t[:n] == pytest.approx(np.arange(n, dtype=float), abs=1e-6)
    k = np.round(t[:n] * 100).astype(int)
    assert np.linalg.norm(rec.pos_ecef[:n] - tr.pos_ecef[k], axis=1).max() < 1e-3   # 1e-9 deg, 0.1 mm heights


def test_export_bad_input(h5, tmp_path):
    (tmp_path / "taken").write_text("x")
    assert_clean_error(["export", "missing.h5", "--format", "csv", "-o", "out"], tmp_path, "missing.h5")
    assert_clean_error(["export", str(h5), "--format", "csv", "-o", "taken"], tmp_path, "not a folder")
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "notes.txt").write_text("keep me")
    assert_clean_error(["export", str(h5), "--format", "rosbag2", "-o", "data"], tmp_path, "not a rosbag2 folder")
    assert (tmp_path / "data" / "notes.txt").read_text() == "keep me"
    assert run_cli(["export", str(h5), "--format", "rosbag2", "-o", "bag"], tmp_path).returncode == 0
    assert run_cli(["export", str(h5), "--format", "rosbag2", "-o", "bag"], tmp_path).returncode == 0  # replaced
    assert sorted(p.name for p in (tmp_path / "bag").iterdir()) == ["bag.db3", "metadata.yaml"]
    proc = run_cli(["export", str(h5), "--format", "kml", "-o", "x.kml"], tmp_path)
    assert proc.returncode == 0 and (tmp_path / "x.kml").is_file()


@pytest.mark.slow
def test_full_airborne_stim300_bag_counts_and_stamps(tmp_path):
    """The whole 1000 s scenario: every message is in the bag, stamped at the file's epochs."""
    path = run("airborne_stim300", out=tmp_path / "air.h5")
    export(path, "rosbag2", tmp_path / "bag", stamp="gps")
    with open_dataset(path) as ds:
        t, imu_t, gnss_t = ds["truth/t"][:], ds["imu/t"][:], ds["gnss/t"][:]
        week, sow = int(ds.attrs["start_gps_week"]), float(ds.attrs["start_gps_sow"])
    base = (week * 604800 + int(sow)) * 10**9
    with Reader(tmp_path / "bag") as r:
        counts = {c.topic: c.msgcount for c in r.connections}
        stamps = {}
        for conn, stamp, _ in r.messages():
            stamps.setdefault(conn.topic, []).append(stamp)
    assert counts["/imu/data"] == len(imu_t) == 100001 and counts["/ground_truth/odom"] == len(t)
    assert counts["/gnss/ant2/fix"] == len(gnss_t)
    assert np.array_equal(stamps["/imu/data"], base + np.round(imu_t * 1e9).astype(np.int64))
    assert np.array_equal(stamps["/gnss/ant0/fix"], base + np.round(gnss_t * 1e9).astype(np.int64))


def test_pyins_reads_the_ned_csvs_and_finds_the_referees_errors(h5, tmp_path):
    """A peer's loader: pyins takes NED DataFrames (lat, lon, alt, VN, VE, VD, roll, pitch, heading in degrees):
    the exported CSVs are that after a column rename, and pyins' state difference of the solution against the
    truth is the referee's error (to pyins' first-order lat/lon scaling)."""
    import pandas as pd
    from pyins import transform as pyins_transform

    export(h5, "csv", tmp_path / "csv", frame="ned-frd")
    names = {"lat_deg": "lat", "lon_deg": "lon", "h_m": "alt", "vel_n_m_per_s": "VN", "vel_e_m_per_s": "VE",
             "vel_d_m_per_s": "VD", "roll_deg": "roll", "pitch_deg": "pitch", "heading_deg": "heading"}

    def load(name):
        df = pd.read_csv(tmp_path / "csv" / name, comment="#").rename(columns=names)
        return df.set_index("t_s")[list(names.values())]

    diff = pyins_transform.compute_state_difference(load("solution_pert.csv"), load("truth.csv"))
    sc = score(h5, h5, solution="pert")
    at = diff.index.get_indexer(sc.errors.t, method="nearest", tolerance=1e-6)   # the CSV's times as parsed
    assert np.all(at >= 0)
    diff = diff.iloc[at]
    np.testing.assert_allclose(sc.errors.pos_enu, diff[["east", "north", "down"]].values * [1, 1, -1], atol=2e-3)
    np.testing.assert_allclose(sc.errors.vel_enu, diff[["VE", "VN", "VD"]].values * [1, 1, -1], atol=1e-9)
    np.testing.assert_allclose(np.degrees(sc.errors.euler), diff[["pitch", "roll", "heading"]].values, atol=1e-7)
