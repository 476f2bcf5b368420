"""The point a solution estimates: the referee compares a solution with the truth at the
point it declares. Authorities: the file's own antenna truth (/gnss/truth/antenna_pos_ecef, antenna_vel_ecef,
written by the GNSS stage), and SPP on error-free observations (noise and multipath off; the broadcast
ionosphere correction is exact by design), which must land on its antenna to millimetres."""
import json

import h5py
import numpy as np
import pytest

import simkit
from simkit import frames, referee
from simkit.estimators import SOLVERS
from simkit.io import open_dataset, read_solution, write_solution
from simkit.referee.truth import at_point, truth_at
from simkit.solution import Solution

from cli_errors import assert_clean_error, run_cli


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    """high_dynamic shortened to 20 s with error-free code and Doppler (noise and multipath off, the truth equal to
    the receiver's atmosphere and orbit models), SPP solved."""
    path = simkit.run("high_dynamic", out=tmp_path_factory.mktemp("point") / "hd.h5",
                      overrides=["scenario.duration_s=20", "gnss.errors.noise=false", "gnss.errors.multipath=false",
                                 "gnss.truth_errors.model='none'"])
    with open_dataset(path) as ds:
        sol = SOLVERS["spp"](ds, {})
    write_solution(path, "spp", sol)
    return path


@pytest.fixture(scope="module")
def antenna_truth(clean):
    with h5py.File(clean, "r") as f:
        return (f["gnss/t"][:], f["gnss/truth/antenna_pos_ecef"][:], f["gnss/truth/antenna_vel_ecef"][:],
                f["gnss/antennas/lever_arm_b"][:])


def test_spp_on_error_free_data_scores_at_millimetres_at_its_antenna(clean, antenna_truth):
    sol = read_solution(clean, "spp")
    assert sol.point == "antenna:0"
    sc = referee.score(referee.read_truth(clean), sol)
    assert sc.meta["point"] == "antenna:0"
    assert sc.statistics["position_3d"]["rms"] < 0.002
    assert sc.statistics["position_3d"]["max"] < 0.005
    # the same estimate declared at the IMU centre is off by the antenna-0 lever arm (the defect's 2.06 m)
    at_imu = referee.score(referee.read_truth(clean), Solution(**{**sol.__dict__, "point": "imu"}))
    lever = np.linalg.norm(antenna_truth[3][0])
    assert at_imu.statistics["position_3d"]["p50"] == pytest.approx(lever, abs=0.005)


def test_truth_at_an_antenna_is_the_files_antenna_truth(clean, antenna_truth):
    """Position truth + C_b^e l and Earth-relative velocity v + C_b^n (w_eb x l), against the GNSS stage."""
    t, pos, vel_ecef, lever = antenna_truth
    truth = referee.read_truth(clean)
    for a in range(lever.shape[0]):
        ref = at_point(truth_at(truth, t), lever[a])
        lla = frames.ecef_to_lla(pos[:, a])
        vel = frames.ecef_to_enu_vec(vel_ecef[:, a], lla[:, 0], lla[:, 1])
        assert np.abs(ref.pos_ecef - pos[:, a]).max() < 1e-6
        assert np.abs(ref.vel_enu - vel).max() < 1e-6


def test_point_is_stored_with_the_solution_and_defaults_to_imu(clean):
    truth = referee.read_truth(clean)
    k = np.arange(0, truth.t.size, 50)
    sol = Solution(t=truth.t[k], pos_ecef=truth.pos_ecef[k], point="lever_b:[0.1, -0.2, 0.3]")
    write_solution(clean, "lever", sol)
    assert read_solution(clean, "lever").point == "lever_b:[0.1, -0.2, 0.3]"
    with h5py.File(clean, "r+") as f:          # a group written before the attribute existed
        del f["solutions/lever"].attrs["point"]
    assert read_solution(clean, "lever").point == "imu"
    with h5py.File(clean, "r+") as f:
        f["solutions/lever"].attrs["point"] = "antenna:one"
    with pytest.raises(simkit.errors.DataFileError, match=r"/solutions/lever attribute point: expected"):
        read_solution(clean, "lever")
    with h5py.File(clean, "r+") as f:
        del f["solutions/lever"]


@pytest.mark.parametrize("point", ["antenna", "antenna:-1", "lever_b:[1, 2]", "lever_b:[1, 2, nan]", "centre"])
def test_a_bad_point_is_refused(point):
    with pytest.raises(ValueError, match="point: expected"):
        Solution(t=np.zeros(1), pos_ecef=np.zeros((1, 3)), point=point)


def test_csv_of_a_third_party_antenna_position_is_scored_at_that_antenna(clean, antenna_truth, tmp_path):
    """A filter reporting antenna 0's phase centre (here its exact truth) scores zero at --point antenna:0, and
    the lever arm's length at the IMU centre."""
    t, pos, _, lever = antenna_truth
    csv = tmp_path / "ant0.csv"
    csv.write_text("t_s,x_ecef_m,y_ecef_m,z_ecef_m\n" + "".join(
        f"{ti!r},{p[0]!r},{p[1]!r},{p[2]!r}\n" for ti, p in zip(t.tolist(), pos[:, 0].tolist())))
    out = run_cli(["score", str(clean), str(csv), "--point", "antenna:0", "--json", str(tmp_path / "s.json")],
                  tmp_path)
    assert out.returncode == 0, out.stderr

    s = json.loads((tmp_path / "s.json").read_text())
    assert s["meta"]["point"] == "antenna:0"
    assert s["statistics"]["position_3d"]["max"] < 1e-6
    run_cli(["score", str(clean), str(csv), "--json", str(tmp_path / "imu.json")], tmp_path)
    s = json.loads((tmp_path / "imu.json").read_text())
    assert s["statistics"]["position_3d"]["p50"] == pytest.approx(np.linalg.norm(lever[0]), abs=1e-6)


def test_bad_point_options_are_one_clean_line(clean, tmp_path):
    csv = tmp_path / "e.csv"
    with h5py.File(clean, "r") as f:
        p = f["truth/pos_ecef"][0].tolist()
    csv.write_text(f"t_s,x_ecef_m,y_ecef_m,z_ecef_m\n0,{p[0]!r},{p[1]!r},{p[2]!r}\n")
    assert_clean_error(["score", str(clean), str(csv), "--point", "antenna:7"], tmp_path,
                       expect="point 'antenna:7': the truth file has 1 antenna(s)")
    assert_clean_error(["score", str(clean), str(csv), "--point", "lever_b:1,2,3"], tmp_path,
                       expect="--point: expected \"imu\"")
    assert_clean_error(["score", str(clean), str(clean), "--solution", "spp", "--point", "imu"], tmp_path,
                       expect="--point: only for a CSV estimate")
