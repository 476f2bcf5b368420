"""The shared Gauss-Markov bank (simkit.processes) against independent authorities: scipy's lfilter runs the same
AR(1) recursion, the closed forms give its stationary variance and autocorrelation, and restarts reproduce the
stationary draw; block cuts do not change a single bit."""
import math

import numpy as np
import pytest
from scipy import signal, stats

from simkit.processes import GaussMarkov, ar1_coefficients


def test_coefficients_are_the_exact_discretisation():
    phi, drive = ar1_coefficients(2.0, 30.0, 0.01)
    assert phi == math.exp(-0.01 / 30.0)
    assert drive == pytest.approx(2.0 * math.sqrt(1.0 - math.exp(-2 * 0.01 / 30.0)), rel=1e-13)
    # stationarity: phi^2 sigma^2 + drive^2 = sigma^2
    assert phi**2 * 4.0 + drive**2 == pytest.approx(4.0, rel=1e-15)
    with pytest.raises(ValueError):
        ar1_coefficients(1.0, 0.0, 0.01)


def test_matches_scipy_lfilter_and_any_block_cut():
    bank = GaussMarkov(0.3, 5.0, 0.02, (3,), np.random.default_rng(11))
    x0 = bank.state.copy()
    w = np.random.default_rng(12).standard_normal((5000, 3))
    cuts = [0, 1, 2, 999, 1000, 4321, 5000]
    out = np.concatenate([bank.advance(w[a:b]) for a, b in zip(cuts[:-1], cuts[1:])])
    phi, drive = ar1_coefficients(0.3, 5.0, 0.02)
    assert np.all(bank.phi == phi) and np.all(bank.drive == drive)
    ref, _ = signal.lfilter([drive], [1.0, -phi], w, axis=0, zi=phi * x0[None, :])
    np.testing.assert_allclose(out, ref, rtol=1e-12, atol=1e-15)
    one = GaussMarkov(0.3, 5.0, 0.02, (3,), np.random.default_rng(11)).advance(w)
    np.testing.assert_array_equal(out, one)


def test_stationary_variance_and_autocorrelation():
    sigma, tau, dt = 1.5, 0.2, 0.01
    bank = GaussMarkov(sigma, tau, dt, (20,), np.random.default_rng(3))
    x = np.concatenate([bank.block(n) for n in (1, 40_000, 9_999)])     # starts stationary: no burn-in
    assert np.std(x) == pytest.approx(sigma, rel=0.02)
    for lag in (1, 10, 20):
        r = np.mean(x[lag:] * x[:-lag]) / np.mean(x * x)
        assert r == pytest.approx(math.exp(-lag * dt / tau), abs=0.01)
    # the first sample is already a N(0, sigma^2) draw across independent processes
    first = np.concatenate([GaussMarkov(sigma, tau, dt, (500,), np.random.default_rng(s)).block(1)[0]
                            for s in range(10)])
    assert stats.kstest(first / sigma, "norm").pvalue > 0.01


def test_restart_and_index_select_part_of_the_bank():
    bank = GaussMarkov(1.0, 10.0, 1.0, (2, 4, 3))          # antenna, satellite, signal
    cols = np.array([1, 3])
    w = np.random.default_rng(5).standard_normal((6, 2, 2, 3))
    restart = np.zeros((6, 2, 2), dtype=bool)
    restart[0] = True                                       # acquisition: stationary start
    restart[4, 1, 0] = True                                 # re-acquisition of one antenna-satellite pair
    x = bank.advance(w, restart, index=(slice(None), cols))
    np.testing.assert_array_equal(x[0], w[0])
    np.testing.assert_array_equal(x[4, 1, 0], w[4, 1, 0])
    phi, drive = ar1_coefficients(1.0, 10.0, 1.0)
    np.testing.assert_allclose(x[4, 0, 0], phi * x[3, 0, 0] + drive * w[4, 0, 0], rtol=1e-15)
    np.testing.assert_array_equal(bank.state[:, cols], x[-1])
    assert not bank.state[:, [0, 2]].any()                  # unselected processes untouched
    with pytest.raises(ValueError, match="shape"):
        bank.advance(w[:, :, :1], restart, index=(slice(None), cols))


def test_a_correlation_time_per_signal():
    """tau per signal (broadcast along the last axis): each signal's processes follow their own exact AR(1)
    recursion, the lag correlation exp(-lag dt / tau) of each."""
    taus = np.array([2.0, 20.0])
    bank = GaussMarkov(1.0, taus[None, None, :], 1.0, (2, 300, 2))
    w = np.random.default_rng(8).standard_normal((4000, 2, 300, 2))
    restart = np.zeros((4000, 2, 300), bool)
    restart[0] = True
    x = bank.advance(w, restart)
    for j, tau in enumerate(taus):
        phi, drive = ar1_coefficients(1.0, tau, 1.0)
        np.testing.assert_allclose(x[7, :, :, j], phi * x[6, :, :, j] + drive * w[7, :, :, j], rtol=1e-14)
        y = x[:, :, :, j]
        r = np.mean(y[1:] * y[:-1]) / np.mean(y * y)
        assert r == pytest.approx(math.exp(-1.0 / tau), abs=0.01)
