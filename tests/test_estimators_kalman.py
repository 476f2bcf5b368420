"""The pure correction kernels against pyins (peer implementation) and closed forms (scalar H-infinity)."""
import numpy as np
import pytest
from pyins import kalman as pyins_kalman

from simkit.estimators import kalman, kalman_update


def _problem(seed, n=15, m=6):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(n, n))
    d = np.exp(rng.uniform(-8, 1, n))  # state scales over nine orders of magnitude, as rad of latitude vs m/s
    p = d[:, None] * (a @ a.T + np.eye(n)) * d
    h = rng.normal(size=(m, n)) / d
    r = np.diag(rng.uniform(0.1, 2.0, m))
    return rng.normal(size=n) * d, p, rng.normal(size=m), h, r


@pytest.mark.parametrize("seed", range(5))
def test_kalman_correction_matches_pyins(seed):
    x, p, z, h, r = _problem(seed)
    ours = kalman_update(x, p, z, h, r)
    x_ref, p_ref, innov_ref = pyins_kalman.correct(x, p, z, h, r)
    assert np.allclose(ours.x, x_ref, rtol=1e-8, atol=0)
    assert np.allclose(ours.P, p_ref, rtol=1e-7, atol=1e-12 * np.abs(p_ref).max())
    # pyins' standardised innovation is L^-1 nu with S = L L^T: its squared norm is the NIS
    assert ours.nis == pytest.approx(float(innov_ref @ innov_ref), rel=1e-9)


def test_hinf_with_vanishing_theta_is_the_kalman_filter():
    x, p, z, h, r = _problem(7)
    nu = z - h @ x
    kf = kalman.correct(x, p, nu, h, r)
    hf = kalman.correct_hinf(x, p, nu, h, r, 1e14)  # alpha -> inf: theta -> 0
    assert np.allclose(hf[0], kf[0], rtol=1e-7, atol=1e-12)
    assert np.allclose(hf[1], kf[1], rtol=1e-6, atol=1e-12 * np.abs(kf[1]).max())
    assert hf[6] == kalman.STATUS_OK and hf[5] > 0


def test_scalar_hinf_closed_form():
    # n = m = 1, H = 1: P+ = 1 / (1/P - theta + 1/R), K = P+ / R; Wu's gamma^2 = alpha P / (1 + P)
    p, r, alpha, nu = 2.0, 0.5, 10.0, 0.3
    theta = (1 + p) / (alpha * p)
    x, p_new, nis, w, gamma, margin, status = kalman.correct_hinf(np.zeros(1), np.array([[p]]), np.array([nu]),
                                                                  np.eye(1), np.array([[r]]), alpha)
    p_expect = 1.0 / (1.0 / p - theta + 1.0 / r)
    assert p_new[0, 0] == pytest.approx(p_expect, rel=1e-12)
    assert x[0] == pytest.approx(p_expect / r * nu, rel=1e-12)
    assert gamma == pytest.approx(np.sqrt(alpha * p / (1 + p)), rel=1e-12)
    assert margin == pytest.approx(p * (1.0 / p - theta + 1.0 / r), rel=1e-12)  # L^T (.) L with L = sqrt(P)
    assert status == kalman.STATUS_OK and nis == pytest.approx(nu**2 / (p + r))


def test_violated_existence_raises_gamma_and_says_so():
    # alpha < 1 makes Wu's gamma violate P^-1 - theta I + H^T R^-1 H > 0 when R is large: never silently
    p, r, alpha = 1.0, 100.0, 0.2
    out = kalman.correct_hinf(np.zeros(1), np.array([[p]]), np.array([0.1]), np.eye(1), np.array([[r]]), alpha)
    gamma, margin, status = out[4], out[5], out[6]
    assert status == kalman.STATUS_GAMMA_RAISED
    assert margin > 0 and 1.0 / p - 1.0 / gamma**2 + 1.0 / r > 0
    assert gamma > np.sqrt(alpha * p / (1 + p))


def test_non_positive_definite_innovation_is_flagged():
    out = kalman.correct(np.zeros(2), np.eye(2), np.ones(1), np.array([[1.0, 0.0]]), np.array([[-2.0]]))
    assert out[4] == kalman.STATUS_S_NOT_PD and np.isnan(out[2])


def test_hinf_does_not_accept_a_nearly_singular_update():
    # p = 1, r = 1e4, alpha = 2 gives Wu's theta = (1 + p) / (alpha p) = 1 and an existence
    # margin 1/p - theta + 1/r = 1e-4 > 0: the condition passes, but P+ = 1 / 1e-4 = 1e4 (10,000 times P).
    # The Kalman posterior is P_kf = 1 / (1/p + 1/r); the weighted rule keeps P+ <= alpha / (alpha - 1) P_kf.
    p, r, alpha = 1.0, 1e4, 2.0
    x, p_new, nis, w, gamma, margin, status = kalman.correct_hinf(np.zeros(1), np.array([[p]]), np.array([1.0]),
                                                                  np.eye(1), np.array([[r]]), alpha)
    p_kf = 1.0 / (1.0 / p + 1.0 / r)
    theta = 1.0 / (alpha * p_kf)  # the weighted rule, closed form for n = m = 1
    assert status == kalman.STATUS_GAMMA_RAISED
    assert gamma == pytest.approx(theta ** -0.5, rel=1e-12)
    assert p_new[0, 0] == pytest.approx(1.0 / (1.0 / p - theta + 1.0 / r), rel=1e-12)
    assert p_new[0, 0] <= alpha / (alpha - 1) * p_kf * (1 + 1e-12)
    assert x[0] == pytest.approx(p_new[0, 0] / r, rel=1e-12)  # K nu with nu = 1


def test_hinf_margin_is_at_least_one_minus_one_over_alpha_on_random_problems():
    # the normalised existence matrix I - theta M^-1/2 L^T L M^-1/2 (M = I + (HL)^T R^-1 HL) has eigenvalues
    # 1 - theta eig(P_kf) >= 1 - 1/alpha under either rule: P+ never exceeds alpha / (alpha - 1) P_kf
    for seed in range(20):
        x, p, z, h, r = _problem(seed)
        r = r * 10.0 ** (seed % 5)  # measurement sigmas from 0.3 to 140 (in units where Wu's H^T H misleads)
        nu = z - h @ x
        p_kf = kalman.correct(x, p, nu, h, r)[1]
        hf = kalman.correct_hinf(x, p, nu, h, r, 10.0)
        l = np.linalg.cholesky(p_kf)
        grow = np.linalg.eigvalsh(np.linalg.solve(l, np.linalg.solve(l, hf[1]).T))
        assert grow.max() <= 10.0 / 9.0 * (1 + 1e-8) and grow.min() >= 1 - 1e-8
