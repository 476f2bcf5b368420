"""The penalised quintic spline of logged trajectories against independent computations: a dense least-squares
solve of the same penalised problem (numpy.linalg.lstsq), scipy's own B-spline derivative, the weighted
quadratic fit (numpy.polyfit) that an infinite penalty leaves, and the white-noise variance of third
differences (20 sigma^2)."""
import numpy as np
import pytest
from scipy.interpolate import BSpline

from simkit.trajectory import pspline


def _data(seed=2, n=200, sigma=1.5):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, 100.0, n))
    t[0], t[-1] = 0.0, 100.0
    truth = 30.0 * np.sin(t / 9.0) + 0.02 * t**2
    return t, truth, truth + rng.normal(0.0, sigma, n), np.full(n, sigma)


def test_solution_equals_a_dense_least_squares_solve_of_the_penalised_problem():
    t, _, y, sig = _data()
    knots = pspline.knots(0.0, 100.0, 0.5)
    rng = np.random.default_rng(4)
    tv = np.linspace(0.0, 100.0, 37)
    v = 30.0 / 9.0 * np.cos(tv / 9.0) + 0.04 * tv + rng.normal(0.0, 0.2, tv.size)
    s, lam, rss = pspline.smooth(knots, t, y, sig, xv=tv, v=v, sigma_v=np.full(tv.size, 0.2))
    n = len(knots) - pspline.DEGREE - 1
    b = BSpline.design_matrix(t, knots, pspline.DEGREE).toarray()
    eye = np.eye(n)
    bv = np.stack([BSpline(knots, eye[j], pspline.DEGREE).derivative()(tv) for j in range(n)], axis=1)
    d3 = np.diff(np.eye(n), 3, axis=0)
    a = np.vstack([b / sig[:, None], bv / 0.2, np.sqrt(lam) * d3])
    rhs = np.concatenate([y / sig, v / 0.2, np.zeros(n - 3)])
    c_ref = np.linalg.lstsq(a, rhs, rcond=None)[0]
    assert s.c == pytest.approx(c_ref, rel=1e-6, abs=1e-6 * np.abs(c_ref).max())
    # the discrepancy principle: the weighted residual sum of squares is the number of samples
    assert rss == pytest.approx(len(t) + len(tv), rel=1e-6)


def test_slope_rows_are_scipys_derivative():
    knots = pspline.knots(0.0, 10.0, 0.7)
    c = np.random.default_rng(1).normal(size=len(knots) - pspline.DEGREE - 1)
    x = np.linspace(0.0, 10.0, 101)
    assert pspline._design(knots, x, 1) @ c == pytest.approx(BSpline(knots, c, pspline.DEGREE).derivative()(x),
                                                            rel=1e-12, abs=1e-12)


def test_an_infinite_penalty_leaves_the_weighted_quadratic_fit():
    rng = np.random.default_rng(5)
    t = np.linspace(0.0, 50.0, 80)
    y = 3.0 - 0.4 * t + 0.01 * t**2 + rng.normal(0.0, 1.0, t.size)
    sig = np.full(t.size, 3.0)              # the noise is stated 3x too large: a quadratic fits "within" it
    s, lam, rss = pspline.smooth(pspline.knots(0.0, 50.0, 1.0), t, y, sig)
    quad = np.polyval(np.polyfit(t, y, 2), t)
    assert rss < t.size
    assert s(t) == pytest.approx(quad, abs=1e-3)     # the largest penalty tried (1e12 relative): 5e-5 here


def test_smoothing_recovers_the_curve_within_the_noise_and_its_derivative():
    t, truth, y, sig = _data(n=400)
    s, _, _ = pspline.smooth(pspline.knots(0.0, 100.0, 0.25), t, y, sig)
    x = np.linspace(2.0, 98.0, 2000)
    err = s(x) - (30.0 * np.sin(x / 9.0) + 0.02 * x**2)
    derr = s(x, 1) - (30.0 / 9.0 * np.cos(x / 9.0) + 0.04 * x)
    print(f"\nRMS error {np.sqrt(np.mean(err**2)):.3f} (noise 1.5), slope {np.sqrt(np.mean(derr**2)):.3f}")
    assert np.sqrt(np.mean(err**2)) < 0.5 * 1.5
    assert np.sqrt(np.mean(derr**2)) < 0.3


def test_noise_estimate_from_third_differences():
    rng = np.random.default_rng(8)
    t = np.arange(0.0, 2000.0, 1.0)
    y = 50.0 * np.sin(t / 30.0) + rng.normal(0.0, 2.0, t.size)
    assert pspline.noise_sigma(t, y) == pytest.approx(2.0, rel=0.06)
    assert np.isnan(pspline.noise_sigma(np.array([0.0, 1.0, 3.0, 7.0, 15.0]), np.zeros(5)))
