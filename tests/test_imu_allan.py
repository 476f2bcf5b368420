"""Each IMU noise term alone: Allan deviation (computed with allantools, the referee) against IEEE Std 952 theory,
rate independence, and the fit recovering the configured terms."""
import math

import numpy as np
import pytest

from simkit.imu import ImuSimulator
from simkit.imu.allan import FLICKER_FLOOR, adev, fit, gm_avar, gm_peak
from simkit.imu.config import GaussMarkovConfig, ImuConfig, SensorSpec

import allantools


def gyro_errors(spec: SensorSpec, rate_hz: float, duration_s: float, seed: int = 7, term: str | None = None,
                truth=None):
    """Measured minus truth (or one error term) of a static gyro with ``spec``, shape (N, 3)."""
    n = int(round(duration_s * rate_hz))
    t = np.arange(n) / rate_hz
    omega = np.zeros((n, 3)) if truth is None else truth(n)
    block = ImuSimulator(ImuConfig(gyro=spec), rate_hz, seed).process(t, omega, np.zeros((n, 3)))
    gyro, errors = block.gyro, block.errors
    return errors[term] if term else gyro - omega


def oadev(y, rate_hz, taus):
    """allantools overlapping ADEV per axis, pooled in variance over the three axes."""
    avar = [allantools.oadev(y[:, a], rate=rate_hz, data_type="freq", taus=np.asarray(taus, float))[1] ** 2
            for a in range(y.shape[1])]
    return np.sqrt(np.mean(avar, axis=0))


def test_white_noise_n_at_1s():
    n = 1e-4                      # rad/sqrt(s)
    y = gyro_errors(SensorSpec(random_walk=n), 100.0, 2000.0)
    a = oadev(y, 100.0, [1.0])[0]
    assert a == pytest.approx(n, rel=0.05)


def test_flicker_floor():
    b = 2e-5                      # IEEE B, rad/s
    y = gyro_errors(SensorSpec(bias_instability=b), 10.0, 40000.0)
    taus = [10.0, 30.0, 100.0]
    a = oadev(y, 10.0, taus)
    assert a == pytest.approx(np.full(3, FLICKER_FLOOR * b), rel=0.10)


def test_rate_random_walk_k_at_3s():
    k = 1e-5                      # rad/s/sqrt(s)
    y = gyro_errors(SensorSpec(rate_random_walk=k), 100.0, 3000.0)
    a = oadev(y, 100.0, [3.0])[0]
    assert a == pytest.approx(k * math.sqrt(3.0 / 3.0), rel=0.10)


def test_quantization():
    step = 1e-5                   # rad increment LSB -> Q = step / sqrt(12)
    q = step / math.sqrt(12.0)
    rng = np.random.default_rng(3)
    y = gyro_errors(SensorSpec(quantization=step), 100.0, 200.0, term="gyro_quantization",
                    truth=lambda n: 0.05 * rng.standard_normal((n, 3)))
    taus = [0.01, 0.1, 1.0]
    a = oadev(y, 100.0, taus)
    assert a == pytest.approx(math.sqrt(3.0) * q / np.array(taus), rel=0.10)


def test_gauss_markov_peak():
    sigma, t_corr = 1e-4, 5.0
    y = gyro_errors(SensorSpec(gauss_markov=(GaussMarkovConfig(sigma, t_corr),)), 10.0, 20000.0)
    tau_peak, adev_peak = gm_peak(sigma, t_corr)
    assert tau_peak == pytest.approx(1.89 * t_corr, rel=0.01)
    a = oadev(y, 10.0, [tau_peak])[0]
    assert a == pytest.approx(adev_peak, rel=0.10)
    # and the whole curve, not just its peak
    taus = [1.0, 30.0]
    assert oadev(y, 10.0, taus) == pytest.approx(np.sqrt(gm_avar(taus, sigma, t_corr)), rel=0.10)


def test_our_adev_matches_allantools():
    y = np.random.default_rng(1).standard_normal((5000, 2)).cumsum(axis=0) * 1e-3
    taus, ours, counts = adev(y, 0.01, [0.01, 0.05, 0.3, 2.0])
    ref = np.stack([allantools.oadev(y[:, a], rate=100.0, data_type="freq", taus=taus)[1] for a in range(2)], 1)
    assert ours == pytest.approx(ref, rel=1e-9)
    assert counts.tolist() == [5000 + 1 - 2 * m for m in (1, 5, 30, 200)]


@pytest.mark.parametrize("rate_hz", [100.0, 400.0, 1000.0])
def test_rate_independence(rate_hz):
    """The same physical spec gives the same ADEV at common tau (theory curve, within 5 %) at any rate."""
    spec = SensorSpec(random_walk=3e-5, bias_instability=1e-5, rate_random_walk=2e-7,
                      gauss_markov=(GaussMarkovConfig(2e-5, 0.5),))
    y = gyro_errors(spec, rate_hz, 1500.0, seed=11)
    taus = np.array([0.1, 0.3, 1.0, 3.0])
    _, a, _ = adev(y, 1.0 / rate_hz, taus)
    measured = np.sqrt(np.mean(a**2, axis=1))
    theory = np.sqrt(3e-5**2 / taus + (FLICKER_FLOOR * 1e-5) ** 2 + 2e-7**2 * taus / 3
                     + gm_avar(taus, 2e-5, 0.5))
    assert measured == pytest.approx(theory, rel=0.05)


def test_rate_independence_pairwise():
    """100 Hz, 400 Hz and 1 kHz records of one spec agree with one another within 5 % at common tau."""
    spec = SensorSpec(random_walk=3e-5, bias_instability=1e-5, gauss_markov=(GaussMarkovConfig(2e-5, 0.5),))
    taus = np.array([0.1, 0.3, 1.0])
    curves = []
    for rate_hz in (100.0, 400.0, 1000.0):
        y = gyro_errors(spec, rate_hz, 1500.0, seed=5)
        curves.append(np.sqrt(np.mean(adev(y, 1.0 / rate_hz, taus)[1] ** 2, axis=1)))
    assert curves[1] == pytest.approx(curves[0], rel=0.05)
    assert curves[2] == pytest.approx(curves[0], rel=0.05)


def _fit_pooled(y, rate_hz, **kw):
    taus, a, counts = adev(y, 1.0 / rate_hz, per_decade=8)
    return fit(taus, np.sqrt(np.mean(a**2, axis=1)), counts * y.shape[1], **kw)


def test_fit_recovers_n_and_b():
    n, b = 2e-5, 1e-5
    y = gyro_errors(SensorSpec(random_walk=n, bias_instability=b), 10.0, 20000.0, seed=3)
    res = _fit_pooled(y, 10.0, terms=("N", "B"))
    assert res.N == pytest.approx(n, rel=0.15)
    assert res.B == pytest.approx(b, rel=0.15)


def test_fit_recovers_n_and_k():
    """K needs the record to hold many intervals where it dominates (K-fits on a short tail scatter by +-50 %)."""
    n, k = 2e-5, 1e-5
    y = gyro_errors(SensorSpec(random_walk=n, rate_random_walk=k), 100.0, 3000.0, seed=3)
    res = _fit_pooled(y, 100.0, terms=("N", "K"))
    assert res.N == pytest.approx(n, rel=0.15)
    assert res.K == pytest.approx(k, rel=0.15)


def test_fit_recovers_q_and_n():
    step, n = 1e-5, 2e-5
    rng = np.random.default_rng(4)
    y = gyro_errors(SensorSpec(quantization=step, random_walk=n), 100.0, 600.0,
                    truth=lambda m: 0.05 * rng.standard_normal((m, 3)))
    res = _fit_pooled(y, 100.0, terms=("Q", "N"))
    assert res.Q == pytest.approx(step / math.sqrt(12.0), rel=0.15)
    assert res.N == pytest.approx(n, rel=0.15)


def test_fit_recovers_gauss_markov_and_white():
    n, sigma, t_corr = 1e-4, 1e-4, 5.0
    y = gyro_errors(SensorSpec(random_walk=n, gauss_markov=(GaussMarkovConfig(sigma, t_corr),)), 10.0, 20000.0, seed=9)
    res = _fit_pooled(y, 10.0, terms=("N",), n_gm=1)
    assert res.N == pytest.approx(n, rel=0.15)
    (s_fit, t_fit), = res.gauss_markov
    assert s_fit == pytest.approx(sigma, rel=0.15)
    assert t_fit == pytest.approx(t_corr, rel=0.15)
