"""kf15_dd: the fixed DD carrier as a tightly coupled attitude measurement.

Authorities: the measurement Jacobian against finite differences of the exact (rotation) measurement function and
against Wang 2018 eq 16 (S_b^T [b x], body-frame DD lines of sight and baselines); the fixed DD ranges against
the file's truth attitude; the filter's attitude against the truth within its own covariance."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import simkit
from simkit.attitude import read_fixed_dd
from simkit.attitude.dd import float_solution
from simkit.attitude.params import AMBIGUITY_DEFAULTS
from simkit.attitude.reading import read
from simkit.attitude.resolve import FixPolicy, resolve
from simkit.attitude.solvers import body_baselines
from simkit.attitude.tight import group_rows
from simkit.estimators import DDCarrier, EstimatorInputError, SOLVERS, model, nav
from simkit.frames import attitude_from_euler
from simkit.io import read_solution
from simkit.referee.stats import reduced_nees
from studies.consistency import error_states
from studies.estimators_dd import truth_at
from tests.cli_errors import assert_clean_error, run_cli


def _geometry(seed):
    rng = np.random.default_rng(seed)
    e = rng.normal(size=(6, 3))
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    los = -(e[1:] - e[0])  # DD rows against satellite 0
    base = np.array([[0.0, 3.965, 0.0], [9.445, 0.0, 0.2]])  # Wang's baselines (m), body
    return np.repeat(los, 2, axis=0), np.tile(base, (5, 1))


def test_dd_jacobian_is_the_derivative_of_the_rotated_baseline():
    c = attitude_from_euler(0.1, -0.3, 2.2).as_matrix()
    los, base = _geometry(1)
    pred, h = model.dd_rows(c, los, base, 15)
    assert np.allclose(pred, np.einsum("mi,ij,mj->m", los, c, base))
    assert np.all(h[:, 3:] == 0.0)
    d = 1e-6
    for j in range(3):
        u = np.zeros(3)
        u[j] = d
        # the filter's error: C~ = exp(-[phi x]) C, to first order (I - [phi x]) C
        cp = Rotation.from_rotvec(-u).as_matrix() @ c
        cm = Rotation.from_rotvec(u).as_matrix() @ c
        numeric = (model.dd_rows(cp, los, base, 15)[0] - model.dd_rows(cm, los, base, 15)[0]) / (2 * d)
        assert np.allclose(h[:, j], numeric, rtol=1e-6, atol=1e-9)


def test_dd_jacobian_is_wang_eq16_in_the_enu_attitude_error():
    c = attitude_from_euler(-0.2, 0.4, 5.0).as_matrix()
    los, base = _geometry(2)
    _, h = model.dd_rows(c, los, base, 15)
    s_b = los @ c  # body-frame DD lines of sight (rows), s_b = C^T G
    wang = np.stack([s_b[i] @ nav.skew(base[i]) for i in range(len(base))])  # S_b^T [b x], body error
    assert np.allclose(h[:, 0:3], wang @ c.T, atol=1e-12)  # body error angle -> ENU: phi_b = C^T phi


def test_dd_carrier_input_is_checked():
    with pytest.raises(EstimatorInputError, match="dd.offsets"):
        DDCarrier([0.0, 1.0], [0, 2], np.zeros((2, 3)), np.zeros((2, 3)), np.zeros(2), np.zeros(8))
    with pytest.raises(EstimatorInputError, match="dd.cov"):
        DDCarrier([0.0], [0, 2], np.zeros((2, 3)), np.zeros((2, 3)), np.zeros(2), np.zeros(3))


@pytest.fixture(scope="module")
def xian(tmp_path_factory):
    """Wang 2018's three-antenna BDS site, 2 minutes, with the scenario's IMU."""
    out = tmp_path_factory.mktemp("dd") / "xian.h5"
    return simkit.run("xian_static_bds", out=out, overrides=["scenario.duration_s=120"])


def test_fixed_dd_ranges_are_the_true_baselines_within_their_covariance(xian):
    with simkit.open(xian) as ds:
        fx = read_fixed_dd(ds)
        q = ds["truth/quat_nb"][:][np.searchsorted(ds["truth/t"][:], fx.t - 1e-9)]
    assert fx.t.size > 100 and not fx.wrong.any()
    c = Rotation.from_quat(q).as_matrix()
    w = []
    roff = np.concatenate([[0], np.cumsum(np.diff(fx.offsets) ** 2)])
    for i in range(fx.t.size):
        a, b = fx.offsets[i], fx.offsets[i + 1]
        res = fx.range_m[a:b] - np.einsum("mi,ij,mj->m", fx.los_enu[a:b], c[i], fx.baseline_b[a:b])
        r = fx.cov[roff[i]:roff[i + 1]].reshape(b - a, b - a)
        w.append(np.linalg.solve(np.linalg.cholesky(r), res))
    w = np.concatenate(w)
    # standardised residuals: unit variance (multipath is correlated in time, so a loose band), no outlier
    assert 0.5 < np.std(w) < 1.5 and np.abs(w).max() < 6.0, (np.std(w), np.abs(w).max())


def test_lli_flags_and_rejected_fixes_keep_rows_out(xian):
    with simkit.open(xian) as ds:
        p = dict(AMBIGUITY_DEFAULTS)
        fd = read(ds, p)
    F = body_baselines(fd.lever_arm)
    grp = float_solution(fd.obs, np.radians(p["mask_deg"]))[0]
    grp = type(grp)(*(getattr(grp, f)[:5] if f not in ("signal", "sat", "ref") and getattr(grp, f) is not None
                      else getattr(grp, f) for f in grp.__dataclass_fields__))
    res = resolve(grp, "lambda", F)
    fd.lli[:] = 0  # start from no flags (the first epochs carry the receiver's initial-lock flags)
    full = group_rows(fd, grp, res, F)
    assert len(full) == res.accepted.sum() and all(len(row[3]) == F.shape[1] * len(grp.sat) for row in full)
    e0 = grp.epochs[np.flatnonzero(res.accepted)[0]]
    fd.lli[grp.signal[0], e0, 2, grp.sat[0]] = 1  # antenna 2: only baseline 2's row of that satellite goes
    flagged = group_rows(fd, grp, res, F)
    row = [r for r in flagged if r[0] == e0][0]
    assert len(row[3]) == F.shape[1] * len(grp.sat) - 1 and row[6] == 1
    fd.lli[grp.signal[0], e0, 0, grp.ref[0]] = 1  # the reference on antenna 0: every row of the epoch goes
    assert all(r[0] != e0 for r in group_rows(fd, grp, res, F))
    rejected = resolve(grp, "lambda", F, FixPolicy(ratio_threshold=1e9))  # nothing passes validation: nothing enters
    assert group_rows(fd, grp, rejected, F) == []


def test_kf15_dd_attitude_is_within_its_covariance_and_beats_kf15(xian):
    with simkit.open(xian) as ds:
        sols = {name: SOLVERS[name](ds, {"align": "attitude"}, False) for name in ("kf15", "kf15_dd")}
        dd = sols["kf15_dd"]
        e = error_states(dd, *truth_at(ds, dd.t))
    m = dd.t >= 30.0
    x, _ = reduced_nees(e[m, 0:3], dd.cov[m, 0:3, 0:3])
    assert 1.0 < x.mean() < 9.0, x.mean()  # 3 dof; one run, errors correlated in time
    assert (dd.extras["dd_rows"][m] > 0).all()
    nis = dd.extras["dd_nis"][m] / dd.extras["dd_rows"][m]
    assert 0.5 < nis.mean() < 1.5
    sig = np.degrees(np.sqrt(dd.cov[m, 2, 2]))
    assert sig.max() < 0.05  # heading sigma from the carrier: hundredths of a degree
    assert np.degrees(np.abs(e[m, 2])).max() < 0.05
    kf = sols["kf15"]
    assert np.degrees(np.sqrt(kf.cov[-1, 2, 2])) > 10 * sig[-1]  # kf15 alone cannot see heading when static


def test_solve_cli_runs_kf15_dd_and_kf21_from_the_attitude_solver(xian):
    args = ["solve", str(xian), "--filter", "kf15_dd", "--filter", "kf21", "--set", "estimator.align=attitude",
            "-q"]
    proc = run_cli(args, xian.parent)
    assert proc.returncode == 0, proc.stderr
    dd = read_solution(xian, "kf15_dd")
    assert dd.config["estimator"] == "kf15_dd" and dd.config["params"]["dd_method"] == "lambda"
    assert dd.config["dd_epochs"] > 100 and "dd_nis" in dd.extras
    k21 = read_solution(xian, "kf21")
    assert k21.config["attitude_source"] == "attitude"  # "auto" with 3 antennas


@pytest.mark.parametrize("args, expect", [
    (["--filter", "kf15_dd", "--set", "estimator.dd_method=guess"], "estimator.dd_method: expected one of"),
    (["--filter", "kf15_dd", "--set", "estimator.dd_gate_p=2"], "estimator.dd_gate_p: expected a probability"),
    (["--filter", "kf21", "--set", "estimator.attitude_source=moon"], "estimator.attitude_source: expected"),
    (["--filter", "kf15_dd", "--set", "estimator.attitude_source=truth"], "estimator.attitude_source: unknown"),
])
def test_bad_dd_arguments_fail_cleanly(xian, args, expect):
    assert_clean_error(["solve", str(xian), *args, "-q"], xian.parent, expect=expect)


def test_attitude_source_needs_three_antennas(tmp_path):
    path = simkit.run("quickstart", out=tmp_path / "q.h5", overrides=["scenario.duration_s=5"])
    assert_clean_error(["solve", str(path), "--filter", "kf21", "--set", "estimator.attitude_source=attitude",
                        "--set", "estimator.align=static", "-q"], tmp_path, expect="needs 3 or more antennas")


def test_the_gate_keeps_a_corrupted_dd_epoch_out(xian):
    from dataclasses import replace

    from simkit.estimators import KalmanFilter15DD, registry

    with simkit.open(xian) as ds:
        p = registry.merged("kf15_dd", {"align": "attitude"})
        imu, gnss = registry.imu_data(ds), registry.gnss_fixes(ds, p)
        init = registry.initial_state(ds, p, imu, gnss)
        dd = registry.dd_carrier(ds, p)
        cfg = registry.filter_config(ds, p, "kf15_dd")
    i = int(np.searchsorted(dd.t, 60.0))
    bad = dd.range_m.copy()
    bad[dd.offsets[i]:dd.offsets[i + 1]] += 0.05  # 5 cm on every row of one epoch: a wrong fix of ~0.25 cycle
    dd_bad = replace(dd, range_m=bad)
    at = lambda sol: np.argmin(np.abs(sol.t - dd.t[i]))  # noqa: E731
    gated = KalmanFilter15DD(cfg, init).run(imu, gnss, dd=dd_bad)
    assert gated.config["dd_rejected"] == 1 and gated.extras["dd_rows"][at(gated)] == 0
    open_ = KalmanFilter15DD(replace(cfg, dd_gate_p=0.0), init).run(imu, gnss, dd=dd_bad)
    assert open_.config["dd_rejected"] == 0 and open_.extras["dd_rows"][at(open_)] > 0
    assert open_.extras["dd_nis"][at(open_)] == gated.extras["dd_nis"][at(gated)] > 100


@pytest.mark.slow
def test_kf15_dd_attitude_nees_is_within_the_chi2_bounds_over_a_monte_carlo(tmp_path):
    from studies.estimators_dd import attitude_nees

    res = attitude_nees("airborne_stim300", runs=6, seconds=150.0, skip_s=60.0, workdir=tmp_path)
    lo, hi = res["bounds_95"]
    assert lo < res["nees_mean"] < hi and res["fraction_inside"] > 0.75, res


def test_kf15_dd_on_a_static_site_aligns_automatically_from_the_fixed_attitude(xian):
    """``simkit solve xian.h5 --filter kf15_dd`` with no align key: "auto" takes the carrier-phase
    attitude (3 antennas fix), reports it, and the heading is held to the DD level (a MEMS gyro cannot
    gyrocompass: "static" would start degrees off and the gate would reject the DD rows)."""
    proc = run_cli(["solve", str(xian), "--filter", "kf15_dd", "-q"], xian.parent)
    assert proc.returncode == 0, proc.stderr
    sol = read_solution(xian, "kf15_dd")
    assert sol.config["align_used"] == "attitude" and sol.config["params"]["align"] == "auto"
    with simkit.open(xian) as ds:
        q, _, _ = truth_at(ds, sol.t)
    err = (Rotation.from_quat(sol.quat_nb) * Rotation.from_quat(q).inv()).magnitude()
    assert np.degrees(err[sol.t > 30]).max() < 0.2 and sol.config["dd_rejected"] == 0


def test_auto_alignment_is_static_on_a_stationary_start_and_in_motion_otherwise(tmp_path):
    """quickstart (2 antennas: no 3-antenna attitude) stands still for 5 s, then drives off. Static only where the
    gyros can gyrocompass: with the file's MEMS model (ADIS16488) the heading comes from the motion; with a gyro
    model of navigation grade (bias and ARW given) the stationary start is used."""
    from simkit.estimators import registry

    nav_grade = {"p0_gyro_bias": 1e-8, "gyro_arw": 1e-8}
    path = simkit.run("quickstart", out=tmp_path / "q.h5", overrides=["scenario.duration_s=30"])
    with simkit.open(path) as ds:
        for span, extra, want in ((4.0, nav_grade, "static"), (4.0, {}, "motion"), (10.0, nav_grade, "motion")):
            p = registry.merged("kf15_dd", {"align_static_s": span, **extra})
            imu, gnss = registry.imu_data(ds), registry.gnss_fixes(ds, p)
            assert registry.resolve_align(ds, p, imu, gnss) == (want, None)
        sol = SOLVERS["kf15_dd"](ds, {"align_static_s": 4.0, **nav_grade}, False)
        assert sol.config["align_used"] == "static"


def test_time_correlated_dd_noise_inflates_only_the_multipath_part(xian):
    from simkit.attitude.tight import correlation_inflation

    with simkit.open(xian) as ds:
        white = read_fixed_dd(ds, {}, "lambda")
        corr = read_fixed_dd(ds, {}, "lambda", correlation_s=30.0)
    assert np.array_equal(white.range_m, corr.range_m) and np.array_equal(white.offsets, corr.offsets)
    f = correlation_inflation(30.0, 1.0)
    m = np.diff(white.offsets)
    starts = np.concatenate([[0], np.cumsum(m ** 2)])
    for i in range(0, len(m), 17):
        w = white.cov[starts[i]:starts[i + 1]].reshape(m[i], m[i])
        mp = (corr.cov[starts[i]:starts[i + 1]].reshape(m[i], m[i]) - w) / (f - 1)  # the multipath part
        assert np.linalg.eigvalsh(mp)[0] > 0 and np.linalg.eigvalsh(w - mp)[0] > 0  # a proper part of R


@pytest.mark.slow
def test_kf15_dd_attitude_nees_on_a_static_site_is_within_the_bounds_with_the_correlated_noise_model(tmp_path):
    """30 s Gauss-Markov carrier multipath on a static site: taken as white the DD update is optimistic (NEES
    4.4, 64 % inside at 10 x 600 s); with dd_correlation_s = 30 the mean is inside the bounds."""
    from studies.estimators_dd import attitude_nees

    res = attitude_nees("xian_static_bds", runs=6, seconds=300.0, skip_s=60.0, workdir=tmp_path,
                        params={"dd_correlation_s": 30.0})
    off = attitude_nees("xian_static_bds", runs=6, seconds=300.0, skip_s=60.0, workdir=tmp_path)
    lo, hi = res["bounds_95"]
    assert lo < res["nees_mean"] < hi and res["fraction_inside"] > 0.75, res
    assert off["nees_mean"] > res["nees_mean"] + 0.8, off
