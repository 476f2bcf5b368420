"""Solutions that do not estimate everything: NaN blocks of a covariance reduce the NEES
dimension (checked against scipy.stats.chi2 and the closed-form quadratic forms of each block); an Euler-only
attitude with a NaN roll (two antennas) is scored on pitch and heading and says what it leaves out; the
covariance of a filter's own error states (d_lat, d_lon, d_h, dv_*, phi_*) gives the +-3 sigma bands."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from scipy.stats import chi2

import simkit
from simkit import frames, referee
from simkit.referee import stats
from simkit.referee.compare import Errors
from simkit.solution import Solution

WGS84_A, WGS84_E2 = 6378137.0, 6.69437999014e-3     # NIMA TR8350.2 table 3.1 / 3.3


@pytest.fixture(scope="module")
def truth(tmp_path_factory):
    path = simkit.run("quickstart", out=tmp_path_factory.mktemp("cons") / "q.h5",
                      overrides=["scenario.duration_s=20"])
    return referee.read_truth(path)


def _pos_vel_estimate(truth, P, rng):
    """Truth every other sample plus ENU position/velocity errors drawn from N(0, P) (K, 6, 6); returns the
    Solution fields and the errors."""
    k = np.arange(0, truth.t.size, 2)
    e = np.einsum("kij,kj->ki", np.linalg.cholesky(P), rng.standard_normal((k.size, 6)))
    lla = frames.ecef_to_lla(truth.pos_ecef[k])
    pos = truth.pos_ecef[k] + frames.enu_to_ecef_vec(e[:, :3], lla[:, 0], lla[:, 1])
    return dict(t=truth.t[k], pos_ecef=pos, vel_enu=truth.vel_enu[k] + e[:, 3:]), e


def test_nan_blocks_reduce_the_nees_dimension(truth):
    """Position and velocity estimated as separate blocks (NaN cross-covariance, as SPP writes it) and, at
    every third epoch, no velocity at all (NaN velocity block): the NEES is the sum of the finite blocks'
    quadratic forms, with 6 or 3 degrees of freedom, and 95 % of epochs fall inside scipy's chi2 bounds."""
    rng = np.random.default_rng(19)
    k = truth.t.size // 2 + truth.t.size % 2
    P = np.zeros((k, 6, 6))
    P[:, :3, :3] = np.diag([0.25, 0.36, 0.81]) + 0.1
    P[:, 3:, 3:] = np.diag([0.01, 0.02, 0.04])
    fields, e = _pos_vel_estimate(truth, P, rng)
    cov = P.copy()
    cov[:, :3, 3:] = cov[:, 3:, :3] = np.nan
    no_vel = np.arange(k) % 3 == 0
    cov[no_vel, 3:, :] = cov[no_vel, :, 3:] = np.nan
    sol = Solution(**fields, cov=cov, state_names=("pos_e", "pos_n", "pos_u", "vel_e", "vel_n", "vel_u"))
    nees = referee.score(truth, sol).nees
    q_pos = np.einsum("ki,ki->k", e[:, :3], np.linalg.solve(P[:, :3, :3], e[:, :3, None])[..., 0])
    q_vel = np.einsum("ki,ki->k", e[:, 3:], np.linalg.solve(P[:, 3:, 3:], e[:, 3:, None])[..., 0])
    expect = np.where(no_vel, q_pos, q_pos + q_vel)
    np.testing.assert_allclose(nees["series"], expect, rtol=1e-6)
    np.testing.assert_array_equal(nees["dof"], np.where(no_vel, 3, 6))
    dof = np.where(no_vel, 3, 6)
    inside = (expect >= chi2.ppf(0.025, dof)) & (expect <= chi2.ppf(0.975, dof))
    assert nees["fraction_inside"] == pytest.approx(inside.mean())
    assert abs(nees["fraction_inside"] - 0.95) < 4 * np.sqrt(0.95 * 0.05 / k)
    total = dof.sum()
    assert nees["mean_bounds"] == pytest.approx([chi2.ppf(0.025, total) / k, chi2.ppf(0.975, total) / k])


def test_an_epoch_without_any_finite_state_leaves_the_test():
    e = np.array([[1.0, 2.0], [np.nan, np.nan], [3.0, np.nan]])
    P = np.array([np.diag([1.0, 4.0]), np.eye(2), [[9.0, np.nan], [np.nan, np.nan]]])
    value, dof = stats.reduced_nees(e, P)
    np.testing.assert_allclose(value, [1.0 + 1.0, np.nan, 1.0])
    np.testing.assert_array_equal(dof, [2, 0, 1])


def test_euler_only_attitude_with_nan_roll_is_scored_on_pitch_and_heading(truth):
    """A two-antenna attitude: pitch and heading, roll NaN by design, no quaternion; errors are the offsets."""
    k = np.arange(0, truth.t.size, 5)
    eul = frames.euler_from_attitude(Rotation.from_quat(truth.quat_nb[k]))
    est = eul + np.radians([0.2, 0.0, -0.3])
    est[:, 1] = np.nan
    sol = Solution(t=truth.t[k], euler=est, cov=np.broadcast_to(np.diag(np.radians([0.2, 0.3]) ** 2),
                                                                (k.size, 2, 2)).copy(),
                   state_names=("pitch", "heading"))
    sc = referee.score(truth, sol)
    assert sc.statistics["pitch"]["mean"] == pytest.approx(0.2, abs=1e-9)
    assert sc.statistics["heading"]["mean"] == pytest.approx(-0.3, abs=1e-9)
    assert sc.meta["not_estimated"] == ["position", "velocity", "roll", "attitude_3d"]
    assert "roll" not in sc.statistics and "attitude_3d" not in sc.statistics
    assert sc.nees["states"] == ["pitch", "heading"] and sc.nees["dof_mean"] == 2
    assert "Not estimated (left out): position, velocity, roll, attitude_3d" in referee.to_markdown(sc)


def test_filter_error_states_give_enu_and_euler_sigma_bands():
    """d_lat / d_lon in radians become metres over the radii of curvature (closed form); at a level attitude
    the heading sigma is the up-misalignment sigma and pitch and roll share the two horizontal ones."""
    lat, h, heading = np.radians(34.0), 400.0, np.radians(30.0)
    n = 4
    lla = np.tile([lat, 0.3, h], (n, 1))
    q = np.tile(frames.quat_from_euler(0.0, 0.0, heading), (n, 1))
    err = Errors(np.arange(n, dtype=float), np.arange(n), np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3)),
                 np.zeros((n, 3)), lla, q)
    names = ("phi_e", "phi_n", "phi_u", "dv_e", "dv_n", "dv_u", "d_lat", "d_lon", "d_h")
    sd = np.array([1e-3, 2e-3, 5e-3, 0.1, 0.2, 0.3, 1e-6, 2e-6, 4.0])
    cov = np.broadcast_to(np.diag(sd**2), (n, 9, 9)).copy()
    bands = stats.sigma_bands(err, cov, names)
    w = 1 - WGS84_E2 * np.sin(lat) ** 2
    r_m, r_n = WGS84_A * (1 - WGS84_E2) / w**1.5, WGS84_A / np.sqrt(w)
    np.testing.assert_allclose(bands["pos_enu"], np.tile([2e-6 * (r_n + h) * np.cos(lat), 1e-6 * (r_m + h), 4.0],
                                                         (n, 1)), rtol=1e-9)
    np.testing.assert_allclose(bands["vel_enu"], np.tile([0.1, 0.2, 0.3], (n, 1)), rtol=1e-12)
    assert bands["euler"][:, 2] == pytest.approx(np.full(n, 5e-3), rel=1e-6)
    np.testing.assert_allclose(bands["euler"][:, 0] ** 2 + bands["euler"][:, 1] ** 2, 1e-6 + 4e-6, rtol=1e-6)


def test_epochs_without_an_estimate_do_not_delay_convergence():
    """A gap in the fixes (NaN) after the error has settled is not a divergence (SPP on error-free data used to
    'converge' only after its last gap); an error above the threshold still counts, wherever the gaps are."""
    t = np.arange(10.0)
    x = np.array([5.0, 3.0, 0.5, 0.2, np.nan, np.nan, 0.1, 0.3, np.nan, 0.2])
    assert stats.convergence_time(t, x, 1.0) == 2.0
    assert stats.convergence_time(t, np.where(t == 7, 2.0, x), 1.0) == 9.0
    assert stats.convergence_time(t, np.where(t == 9, 2.0, x), 1.0) is None
    assert stats.convergence_time(t, np.where(t >= 8, np.nan, np.where(t == 7, 2.0, x)), 1.0) is None
    assert stats.convergence_time(t, np.abs(x) * 0.1, 1.0) == 0.0


def test_chi_square_bounds_of_a_mean_match_the_closed_forms_of_two_degrees_of_freedom():
    """One chi-square value with 2 dof is exponential (mean 2): quantile -2 ln(1 - q). The mean of K such values
    is Gamma(K, scale 2 / K). The NEES studies take their N-run bounds from the same function as the referee."""
    from scipy.stats import gamma

    from simkit.referee.stats import chi_square, mean_bounds

    assert np.allclose(mean_bounds(2, 1, 0.95), (-2 * np.log(0.975), -2 * np.log(0.025)), rtol=1e-12)
    lo, hi = mean_bounds(2 * 50, 50, 0.9)
    assert np.allclose((lo, hi), gamma.ppf([0.05, 0.95], 50, scale=2 / 50), rtol=1e-10)
    out = chi_square(np.full(50, 2.0), np.full(50, 2.0), 0.9)
    assert np.allclose(out["mean_bounds"], (lo, hi), rtol=1e-12)
