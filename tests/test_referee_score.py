"""``simkit score`` against authorities: zero error for the truth itself; a known bias and noise recovered
(closed form: sample mean and standard deviation); NEES / NIS follow the chi-square law (scipy.stats.chi2) and an
overconfident covariance (x 0.1) fails; a NED / forward-right-down CSV scores exactly as the equivalent ENU
solution; estimate-minus-truth agrees with pyins' ``transform.compute_state_difference`` (a peer's NED errors)."""
import json

import numpy as np
import pandas as pd
import pymap3d
import pytest
from pyins import transform as pyins_transform
from scipy.spatial.transform import Rotation

import simkit
from simkit import referee
from simkit.io import write_solution
from simkit.solution import Solution

SWAP = np.array([[0.0, 1, 0], [1, 0, 0], [0, 0, -1]])   # ENU <-> NED and RFU <-> FRD, written out here


@pytest.fixture(scope="module")
def h5(tmp_path_factory):
    """quickstart shortened to 20 s at 100 Hz: standstill, acceleration and the start of the turn."""
    return simkit.run("quickstart", out=tmp_path_factory.mktemp("score") / "q.h5",
                      overrides=["scenario.duration_s=20"])


@pytest.fixture(scope="module")
def truth(h5):
    return referee.read_truth(h5)


def _enu_offsets_to_ecef(truth_sub, d_enu):
    """ECEF positions displaced by ENU offsets, with pymap3d's rotation (an authority independent of ours)."""
    lat, lon, _ = pymap3d.ecef2geodetic(*truth_sub.pos_ecef.T, deg=False)
    du, dv, dw = pymap3d.enu2uvw(d_enu[:, 0], d_enu[:, 1], d_enu[:, 2], lat, lon, deg=False)
    return truth_sub.pos_ecef + np.stack([du, dv, dw], axis=1)


def _perturbed(truth, step=10, pos_bias=(0.0, 0.0, 0.0), pos_sd=0.0, vel_sd=0.0, heading_bias=0.0, seed=3):
    """Truth every ``step`` samples plus ENU position bias/noise, ENU velocity noise and a heading bias."""
    rng = np.random.default_rng(seed)
    sub = referee.Truth(*(x[::step] for x in (truth.t, truth.pos_ecef, truth.vel_enu, truth.quat_nb)))
    k = len(sub.t)
    d_pos = np.asarray(pos_bias) + pos_sd * rng.standard_normal((k, 3))
    d_vel = vel_sd * rng.standard_normal((k, 3))
    # a heading error is a rotation about the ENU up axis by -heading_bias (heading clockwise from north)
    rot = Rotation.from_rotvec([0, 0, -heading_bias]) * Rotation.from_quat(sub.quat_nb)
    return Solution(t=sub.t, pos_ecef=_enu_offsets_to_ecef(sub, d_pos), vel_enu=sub.vel_enu + d_vel,
                    quat_nb=rot.as_quat()), d_pos, d_vel


def test_truth_scored_against_itself_has_zero_error(truth):
    sol = Solution(t=truth.t, pos_ecef=truth.pos_ecef, vel_enu=truth.vel_enu, quat_nb=truth.quat_nb)
    sc = referee.score(truth, sol)
    for q, row in sc.statistics.items():
        assert row["max"] < 1e-9, (q, row)
    assert all(c["time_s"] == 0.0 for c in sc.convergence.values())


def test_known_bias_and_noise_are_recovered(truth):
    bias, sd = np.array([1.5, -0.7, 2.0]), 0.3
    sol, d_pos, _ = _perturbed(truth, pos_bias=bias, pos_sd=sd, vel_sd=0.05, heading_bias=np.radians(0.4))
    sc = referee.score(truth, sol)
    k = sc.meta["epochs_scored"]
    assert k == len(sol.t)
    # the scorer returns exactly the injected offsets (pymap3d's rotation vs ours: < 1 um)
    np.testing.assert_allclose(sc.errors.pos_enu, d_pos, atol=1e-6)
    for axis, name in enumerate(("east", "north", "up")):
        row = sc.statistics[name]
        assert abs(row["mean"] - bias[axis]) < 4 * sd / np.sqrt(k)           # sample mean: sd / sqrt(K)
        assert abs(row["std"] / sd - 1) < 4 / np.sqrt(2 * k)                 # sample sd: sd / sqrt(2K)
        assert row["rms"] == pytest.approx(np.hypot(row["mean"], row["std"]), rel=1e-12)
    assert sc.statistics["heading"]["mean"] == pytest.approx(0.4, abs=1e-9)
    assert abs(sc.statistics["pitch"]["max"]) < 1e-9 and abs(sc.statistics["roll"]["max"]) < 1e-9
    assert sc.statistics["attitude_3d"]["mean"] == pytest.approx(0.4, abs=1e-9)
    assert abs(sc.statistics["vel_up"]["std"] / 0.05 - 1) < 4 / np.sqrt(2 * k)


def _with_cov(sol, sd_pos, sd_vel, scale=1.0):
    names = ("pos_e", "pos_n", "pos_u", "vel_e", "vel_n", "vel_u")
    var = np.array([sd_pos] * 3 + [sd_vel] * 3) ** 2 * scale
    cov = np.broadcast_to(np.diag(var), (len(sol.t), 6, 6)).copy()
    return Solution(t=sol.t, pos_ecef=sol.pos_ecef, vel_enu=sol.vel_enu, quat_nb=sol.quat_nb, cov=cov,
                    state_names=names)


def test_nees_is_chi_square_and_an_overconfident_filter_fails(truth):
    sol, _, _ = _perturbed(truth, step=2, pos_sd=0.8, vel_sd=0.03, seed=11)
    spec = referee.parse_spec({"consistency": {"nees_min_fraction_inside": 0.9}})
    good = referee.score(truth, _with_cov(sol, 0.8, 0.03), spec)
    k = good.nees["epochs"]
    assert good.nees["states"] == ["pos_e", "pos_n", "pos_u", "vel_e", "vel_n", "vel_u"]
    # consistent: 95 % of chi2(6) draws inside the 95 % bounds (binomial sd sqrt(.95 .05 / K)), mean 6
    assert abs(good.nees["fraction_inside"] - 0.95) < 4 * np.sqrt(0.95 * 0.05 / k)
    lo, hi = good.nees["mean_bounds"]
    assert lo < good.nees["mean"] < hi and lo < 6 < hi
    assert good.passed
    bad = referee.score(truth, _with_cov(sol, 0.8, 0.03, scale=0.1), spec)
    assert bad.nees["mean"] == pytest.approx(10 * good.nees["mean"], rel=1e-9)
    assert bad.nees["fraction_inside"] < 0.2 and not bad.passed
    assert "NEES" in [c for c in bad.checks if not c["passed"]][0]["name"]


def test_nis_from_filter_extras_is_tested_against_chi_square(truth):
    sol, _, _ = _perturbed(truth, step=2)
    rng = np.random.default_rng(5)
    dof = np.where(np.arange(len(sol.t)) % 2 == 0, 4.0, 0.0)         # an update every other epoch
    nis = np.where(dof > 0, rng.chisquare(np.maximum(dof, 1)), np.nan)
    sol = Solution(t=sol.t, pos_ecef=sol.pos_ecef, extras={"nis": nis, "nis_dof": dof})
    sc = referee.score(truth, sol, referee.parse_spec({"consistency": {"nis_min_fraction_inside": 0.9}}))
    assert sc.nis["epochs"] == int((dof > 0).sum())
    assert abs(sc.nis["fraction_inside"] - 0.95) < 4 * np.sqrt(0.95 * 0.05 / sc.nis["epochs"])
    assert sc.passed


def _ned_csv(path, sol, quaternion: bool):
    """The solution written as a NED / forward-right-down CSV, converted here with explicit matrices."""
    lat, lon, h = pymap3d.ecef2geodetic(*sol.pos_ecef.T, deg=True)
    vel_ned = sol.vel_enu @ SWAP.T
    c_ned_frd = SWAP @ Rotation.from_quat(sol.quat_nb).as_matrix() @ SWAP
    cols = {"t_s": sol.t, "lat_deg": lat, "lon_deg": lon, "h_m": h, "vel_n_m_per_s": vel_ned[:, 0],
            "vel_e_m_per_s": vel_ned[:, 1], "vel_d_m_per_s": vel_ned[:, 2],
            "sd_n_m": np.full(len(sol.t), 0.5), "sd_e_m": np.full(len(sol.t), 0.5),
            "sd_d_m": np.full(len(sol.t), 0.8)}
    if quaternion:   # scalar-first, body FRD -> NED
        q = Rotation.from_matrix(c_ned_frd).as_quat()
        cols.update(q_ned_w=q[:, 3], q_ned_x=q[:, 0], q_ned_y=q[:, 1], q_ned_z=q[:, 2])
    else:            # aerospace yaw-pitch-roll of the FRD->NED matrix, degrees
        ypr = Rotation.from_matrix(c_ned_frd).as_euler("ZYX", degrees=True)
        cols.update(roll_deg=ypr[:, 2], pitch_deg=ypr[:, 1], heading_deg=np.mod(ypr[:, 0], 360))
    frame = pd.DataFrame(cols)
    path.write_text("# a third-party filter's output, NED / FRD\n" + frame.to_csv(index=False, float_format="%.12f"))
    return path


@pytest.mark.parametrize("quaternion", [False, True])
def test_ned_frd_csv_scores_like_the_enu_solution(h5, truth, tmp_path, quaternion):
    sol, _, _ = _perturbed(truth, step=20, pos_bias=(0.3, -0.2, 0.5), pos_sd=0.2, vel_sd=0.02,
                           heading_bias=np.radians(1.0))
    names = ("pos_e", "pos_n", "pos_u")
    cov = np.broadcast_to(np.diag([0.25, 0.25, 0.64]), (len(sol.t), 3, 3)).copy()
    enu = Solution(t=sol.t, pos_ecef=sol.pos_ecef, vel_enu=sol.vel_enu, quat_nb=sol.quat_nb, cov=cov,
                   state_names=names)
    copy = tmp_path / "with_solution.h5"
    copy.write_bytes(h5.read_bytes())
    write_solution(copy, "mine", enu)
    a = referee.score(truth, referee.load_estimate(copy)[0])
    b = referee.score(truth, referee.load_estimate(_ned_csv(tmp_path / "ned.csv", sol, quaternion))[0])
    for q in a.statistics:
        for s in ("rms", "max", "p95"):
            tol = 1e-6 if q in ("pitch", "roll", "heading", "attitude_3d") else 2e-6   # 12 printed digits
            assert b.statistics[q][s] == pytest.approx(a.statistics[q][s], abs=tol), (q, s)
    assert b.nees["mean"] == pytest.approx(a.nees["mean"], rel=1e-5)


def test_errors_agree_with_pyins_state_difference(truth):
    sol, _, _ = _perturbed(truth, step=5, pos_bias=(2.0, -1.0, 3.0), pos_sd=1.0, vel_sd=0.1,
                           heading_bias=np.radians(0.7))
    sc = referee.score(truth, sol)

    def frame(t, pos_ecef, vel_enu, quat):
        lat, lon, h = pymap3d.ecef2geodetic(*pos_ecef.T, deg=True)
        rph = Rotation.from_matrix(SWAP @ Rotation.from_quat(quat).as_matrix() @ SWAP).as_euler("ZYX", True)
        vel = vel_enu @ SWAP.T
        return pd.DataFrame({"lat": lat, "lon": lon, "alt": h, "VN": vel[:, 0], "VE": vel[:, 1], "VD": vel[:, 2],
                             "roll": rph[:, 2], "pitch": rph[:, 1], "heading": np.mod(rph[:, 0], 360)}, index=t)

    est = frame(sol.t, sol.pos_ecef, sol.vel_enu, sol.quat_nb)
    ref = frame(truth.t, truth.pos_ecef, truth.vel_enu, truth.quat_nb)
    diff = pyins_transform.compute_state_difference(est, ref)       # pyins: first minus second, NED
    diff = diff.loc[sol.t]
    # pyins scales lat/lon differences by principal radii (first order): mm agreement for metre offsets
    np.testing.assert_allclose(sc.errors.pos_enu, diff[["east", "north", "down"]].values * [1, 1, -1], atol=2e-3)
    np.testing.assert_allclose(sc.errors.vel_enu, diff[["VE", "VN", "VD"]].values * [1, 1, -1], atol=1e-9)
    np.testing.assert_allclose(np.degrees(sc.errors.euler), diff[["pitch", "roll", "heading"]].values, atol=1e-7)


def test_estimate_outside_the_truth_span_is_a_clear_error(truth):
    sol = Solution(t=truth.t[-1] + 1 + np.arange(5.0), pos_ecef=np.zeros((5, 3)))
    with pytest.raises(referee.RefereeInputError, match=r"do not overlap the truth span"):
        referee.score(truth, sol, where="est.csv")
    part = Solution(t=truth.t[-1] - 1.0 + np.arange(4.0), pos_ecef=np.tile(truth.pos_ecef[-1], (4, 1)))
    assert referee.score(truth, part).meta == {"epochs_scored": 2, "epochs_outside_truth": 2,
                                               "t_first_s": truth.t[-1] - 1.0, "t_last_s": truth.t[-1],
                                               "point": "imu", "not_estimated": ["velocity", "attitude"]}


def test_spec_limits_pass_and_fail_with_named_quantities(truth):
    sol, _, _ = _perturbed(truth, pos_bias=(0.0, 0.0, 3.0), heading_bias=np.radians(0.2))
    spec = referee.parse_spec({"limits": {"horizontal": {"rms_m": 0.1}, "up": {"max_m": 1.0},
                                          "heading": {"rms_deg": 0.5}},
                               "convergence": {"heading": {"threshold_deg": 0.3, "max_time_s": 1.0}}})
    sc = referee.score(truth, sol, spec)
    verdicts = {c["name"]: c["passed"] for c in sc.checks}
    assert verdicts == {"horizontal.rms_m <= 0.1": True, "up.max_m <= 1": False, "heading.rms_deg <= 0.5": True,
                        "heading converged to 0.3 deg within 1 s": True}
    assert not sc.passed
    payload = json.loads(referee.to_json(sc, "x"))
    assert payload["passed"] is False and payload["units"]["up"] == "m"


@pytest.mark.parametrize("data, expect", [
    ({"limit": {}}, "unknown section [limit] (did you mean 'limits'?)"),
    ({"limits": {"horizontl": {"rms_m": 1}}}, "limits.horizontl: unknown quantity (did you mean 'horizontal'?)"),
    ({"limits": {"heading": {"rms_m": 1}}}, "limits.heading.rms_m: unknown statistic (did you mean 'rms_deg'?)"),
    ({"limits": {"up": {"rms_m": -1}}}, "limits.up.rms_m: expected a positive number, got -1"),
    ({"convergence": {"up": {"max_time_s": 3}}}, "convergence.up: missing threshold_m"),
    ({"consistency": {"nees_min_fraction_inside": 1.5}}, "expected a number in (0, 1]"),
])
def test_bad_spec_names_the_key(data, expect):
    with pytest.raises(referee.RefereeInputError, match=None) as info:
        referee.parse_spec(data, "pass.toml")
    assert str(info.value).startswith("pass.toml: ") and expect in str(info.value)


def test_csv_full_covariance_columns_give_the_same_nees_as_the_solution(h5, truth, tmp_path):
    """A correlated 2x2 horizontal covariance as cov_<a>__<b> columns (NED names) against the same covariance
    stored in ENU order: the NEES is a property of the error, not of the state order or the frame names."""
    sol, _, _ = _perturbed(truth, step=20, pos_sd=0.3, seed=8)
    p_enu = np.array([[0.09, 0.03], [0.03, 0.16]])          # (east, north)
    cov = np.broadcast_to(p_enu, (len(sol.t), 2, 2)).copy()
    ref = referee.score(truth, Solution(t=sol.t, pos_ecef=sol.pos_ecef, cov=cov, state_names=("pos_e", "pos_n")))
    x, y, z = sol.pos_ecef.T
    rows = "".join(f"{float(t)!r},{float(a)!r},{float(b)!r},{float(c)!r},0.16,0.09,0.03\n"
                   for t, a, b, c in zip(sol.t, x, y, z))
    csv = tmp_path / "cov.csv"
    csv.write_text("t_s,x_ecef_m,y_ecef_m,z_ecef_m,cov_pos_n__pos_n,cov_pos_e__pos_e,cov_pos_n__pos_e\n" + rows)
    got = referee.score(truth, referee.read_csv(csv))
    assert got.nees["states"] == ["pos_n", "pos_e"]
    np.testing.assert_allclose(got.nees["series"], ref.nees["series"], rtol=1e-9)
    bad = tmp_path / "bad.csv"
    bad.write_text("t_s,x_ecef_m,y_ecef_m,z_ecef_m,cov_pos_x__pos_n\n0,1,2,3,4\n")
    with pytest.raises(referee.RefereeInputError, match=r"column cov_pos_x__pos_n: expected cov_<a>__<b>"):
        referee.read_csv(bad)


def test_truth_window_brackets_the_estimate_and_scores_the_same(h5, truth):
    part = referee.read_truth(h5, 5.003, 6.5)
    assert part.t[0] <= 5.003 < part.t[1] and part.t[-2] < 6.5 <= part.t[-1]
    assert len(part.t) == 151   # 5.00 .. 6.50 s at 100 Hz
    sol, _, _ = _perturbed(truth, step=7, pos_sd=0.2)
    inside = (sol.t >= 5.003) & (sol.t <= 6.5)
    sub = Solution(t=sol.t[inside], pos_ecef=sol.pos_ecef[inside])
    a, b = referee.score(truth, sub), referee.score(part, sub)
    assert a.statistics == b.statistics
