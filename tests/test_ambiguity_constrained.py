"""Baseline-constrained ILS: the exact inner problems, C-LAMBDA vs LAMBDA success rates, multivariate attitude."""
import numpy as np
import pytest
from scipy.optimize import minimize
from scipy.spatial.transform import Rotation

from simkit import ambiguity as amb
from simkit.ambiguity.inner import rotation_fit, sphere_fit
from simkit.gnss.differencing import float_solution
from studies.ambiguity import GPS_L1_WAVELENGTH_M, format_table, simulate_epochs, sky_uniform_los, success_table


def _sphere_reference(c, W, length):
    """Global minimum on the sphere by a dense angular grid refined with scipy (independent of the secular eq.)."""
    th, ph = np.meshgrid(np.linspace(0, np.pi, 181), np.linspace(-np.pi, np.pi, 361), indexing="ij")

    def pts(t, p):
        return length * np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)

    def cost(x):
        r = c - x
        return np.einsum("...i,ij,...j->...", r, W, r)

    g = cost(pts(th, ph))
    i = np.unravel_index(np.argmin(g), g.shape)
    res = minimize(lambda v: cost(pts(v[0], v[1])), [th[i], ph[i]], method="Nelder-Mead",
                   options={"xatol": 1e-12, "fatol": 1e-14, "maxiter": 4000})
    return res.fun


def test_sphere_fit_is_the_global_minimum():
    rng = np.random.default_rng(1)
    for k in range(40):
        A = rng.standard_normal((3, 3))
        W = A @ A.T + 0.05 * np.eye(3)
        length = rng.uniform(0.5, 2.0)
        c = rng.standard_normal(3) * (0.2 if k % 2 else 2.0)  # inside and outside the sphere
        w, U = np.linalg.eigh(W)
        out = np.empty(3)
        ours = sphere_fit(c, U, w, length, out)
        assert np.linalg.norm(out) == pytest.approx(length, rel=1e-12)
        assert ours == pytest.approx((c - out) @ W @ (c - out), rel=1e-10, abs=1e-14)
        assert ours <= _sphere_reference(c, W, length) * (1 + 1e-9) + 1e-12


def test_rotation_fit_recovers_a_rotation():
    rng = np.random.default_rng(2)
    F = np.array([[1.2, 0.1, 0.0], [0.0, 2.0, 0.05]]).T  # two body baselines (3, 2)
    for _ in range(20):
        R = Rotation.random(random_state=rng).as_matrix()
        A = rng.standard_normal((6, 6))
        W = np.linalg.inv(1e-6 * (A @ A.T + np.eye(6)))
        c = (R @ F).T.ravel() + 1e-3 * rng.standard_normal(6)
        out = np.empty(9)
        cost = rotation_fit(c, W, F, out)
        Rf = out.reshape(3, 3)
        np.testing.assert_allclose(Rf @ Rf.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(Rf) == pytest.approx(1.0)
        assert np.degrees(np.linalg.norm(Rotation.from_matrix(Rf @ R.T).as_rotvec())) < 0.5
        # a local minimum: no small rotation lowers the cost
        for _ in range(10):
            dR = Rotation.from_rotvec(1e-4 * rng.standard_normal(3)).as_matrix()
            r = c - (Rf @ dR @ F).T.ravel()
            assert r @ W @ r >= cost - 1e-9 * max(cost, 1.0)


def test_constrained_beats_plain_lambda_at_5_and_6_satellites():
    rows = success_table(n_sats=(5, 6), trials=300, seed=0)
    print("\n" + format_table(rows))
    five, six = rows
    assert six["ils"] <= 0.4 and six["constrained"] >= 0.85
    assert five["constrained"] - five["ils"] >= 0.4
    for r in rows:
        assert r["unfinished"] == 0
        assert abs(r["ils"] - r["bootstrap"]) < 0.1  # LAMBDA's empirical rate agrees with its IB estimate


def test_constrained_batch_equals_single_epoch_calls():
    rows = _epochs(6, 20, r=1, seed=4)
    fs, F, a_true, _ = rows
    length = np.linalg.norm(F[:, 0])
    batch = amb.baseline_constrained_ils(fs.a_hat, fs.Qa, fs.b_hat, fs.Qb, fs.Qba, length)
    for k in range(5):
        one = amb.baseline_constrained_ils(fs.a_hat[k], fs.Qa[k], fs.b_hat[k], fs.Qb[k], fs.Qba[k], length)
        np.testing.assert_array_equal(one.candidates, batch.candidates[k])
        np.testing.assert_allclose(one.baselines, batch.baselines[k])
        assert np.linalg.norm(one.baselines[0]) == pytest.approx(length, rel=1e-12)


def _epochs(n_sats, trials, r, seed):
    rng = np.random.default_rng(seed)
    F = np.array([[0.0, 1.5, 0.0], [1.0, 0.2, 0.0]])[:r].T  # body baselines (3, r), m
    R = Rotation.random(trials, random_state=rng).as_matrix()
    b = R @ F  # (trials, 3, r)
    los = sky_uniform_los(rng, n_sats, trials)
    G, carrier, code, a_true = simulate_epochs(rng, los, b, GPS_L1_WAVELENGTH_M, 0.003, 0.30)
    return float_solution(G, carrier, code, GPS_L1_WAVELENGTH_M, 0.003, 0.30), F, a_true, R


def test_multivariate_attitude_solver():
    fs, F, a_true, R_true = _epochs(6, 60, r=2, seed=8)
    truth = a_true.reshape(len(a_true), -1)
    res = amb.attitude_constrained_ils(fs.a_hat, fs.Qa, fs.b_hat, fs.Qb, fs.Qba, F, n_cands=1)
    ok = np.all(res.candidates[:, 0] == truth, axis=1)
    plain = amb.ils_batch(fs.a_hat, fs.Qa, n_cands=1)
    ok_plain = np.all(plain.candidates[:, 0] == truth, axis=1)
    assert res.finished.all()
    assert ok.mean() >= 0.9 and ok.mean() > ok_plain.mean() + 0.3
    err = [np.degrees(np.linalg.norm(Rotation.from_matrix(Rf @ Rt.T).as_rotvec()))
           for Rf, Rt in zip(res.rotations[ok, 0], R_true[ok])]
    assert max(err) < 2.0  # DD carrier sigma 6 mm on 1-1.5 m baselines: ~0.3-0.4 deg per axis (1 sigma)
    np.testing.assert_allclose(res.baselines[ok, 0], res.rotations[ok, 0] @ F)


def test_constrained_input_errors():
    with pytest.raises(amb.AmbiguityInputError, match="length"):
        amb.baseline_constrained_ils(np.zeros(3), np.eye(3), np.zeros(3), np.eye(3), np.zeros((3, 3)), -1.0)
    with pytest.raises(amb.AmbiguityInputError, match="Qba"):
        amb.baseline_constrained_ils(np.zeros(3), np.eye(3), np.zeros(3), np.eye(3), np.zeros((3, 2)), 1.0)
