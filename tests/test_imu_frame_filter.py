"""The IMU's frame-wise filters (simkit.imu.noise.FrameFilter) against scipy.signal, the authority for the same
recursions: the Butterworth design, sosfilt for the bandwidth low-pass, lfilter for the Gauss-Markov and flicker
branches; any block cut gives the same bits, and a truth + IMU run does not start numba or scipy.signal."""
import math
import subprocess
import sys

import numpy as np
import pytest
from scipy import signal

from simkit.imu.noise import FRAME, Flicker, LowPass, butter2_lowpass, flicker_design, gauss_markov

CUTS = [0, 1, 2, FRAME - 1, FRAME, FRAME + 1, 1000, 4097, 20000]


def pieces(fn, n):
    cuts = [c for c in CUTS if c < n] + [n]
    return np.concatenate([fn(b - a) for a, b in zip(cuts[:-1], cuts[1:])])


@pytest.mark.parametrize("cutoff, rate", [(262.0, 1000.0), (262.0, 2000.0), (10.0, 100.0), (49.0, 100.0)])
def test_butterworth_design_equals_scipy(cutoff, rate):
    np.testing.assert_allclose(butter2_lowpass(cutoff, 1.0 / rate),
                               signal.butter(2, cutoff, fs=rate, output="sos")[0], rtol=0, atol=1e-15)


def test_lowpass_equals_sosfilt_from_steady_state_and_any_cut():
    x = np.random.default_rng(0).standard_normal((20000, 3)) + np.array([5.0, -2.0, 9.8])
    sos = signal.butter(2, 262.0, fs=1000.0, output="sos")
    ref, _ = signal.sosfilt(sos, x, axis=0, zi=signal.sosfilt_zi(sos)[:, :, None] * x[:1][None])
    lp = LowPass(262.0, 1e-3)
    cut = pieces(lambda n, pos=[0]: (lp.block(x[pos[0]:pos[0] + n]), pos.__setitem__(0, pos[0] + n))[0], len(x))
    np.testing.assert_allclose(cut, ref, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(cut, LowPass(262.0, 1e-3).block(x))


@pytest.mark.parametrize("cutoff, rate, tol", [(0.5, 1000.0, 1e-10), (10.0, 1000.0, 1e-12), (100.0, 400.0, 1e-12)])
def test_slow_and_fast_lowpass_batches_equal_sosfilt_and_any_cut(cutoff, rate, tol):
    """Batches of 64 frames in closed form where A^L decays (10 Hz and faster here), the frame-by-frame recursion
    where it does not (0.5 Hz at 1 kHz): both within ``tol`` of the inputs' size from scipy's per-sample recursion,
    on a record of several batches (at 0.5 Hz both start states, ours and sosfilt_zi's, solve a system with
    condition ~1e6: 1e-11 apart at the first sample already)."""
    x = 20.0 * np.random.default_rng(3).standard_normal((3 * 4096 + 77, 3)) + np.array([5.0, -2.0, 9.8])
    sos = signal.butter(2, cutoff, fs=rate, output="sos")
    ref, _ = signal.sosfilt(sos, x, axis=0, zi=signal.sosfilt_zi(sos)[:, :, None] * x[:1][None])
    lp = LowPass(cutoff, 1.0 / rate)
    cut = pieces(lambda n, pos=[0]: (lp.block(x[pos[0]:pos[0] + n]), pos.__setitem__(0, pos[0] + n))[0], len(x))
    np.testing.assert_allclose(cut, ref, rtol=0, atol=tol * np.abs(x).max())
    whole = LowPass(cutoff, 1.0 / rate)
    np.testing.assert_array_equal(cut, whole.block(x))
    assert whole.filter.count == (1 if cutoff < 1.0 else 64)


def test_gauss_markov_equals_lfilter_and_any_cut():
    sigma, tau, dt = 2e-5, 30.0, 1e-3
    phi, drive = math.exp(-dt / tau), sigma * math.sqrt(-math.expm1(-2 * dt / tau))
    rng = np.random.default_rng(4)
    x0, w = sigma * rng.standard_normal(3), rng.standard_normal((20000, 3))   # the draws, in the same order
    ref, _ = signal.lfilter([drive], [1.0, -phi], w, axis=0, zi=phi * x0[None, :])
    gm = gauss_markov(sigma, tau, dt, np.random.default_rng(4))
    cut = pieces(gm.block, 20000)
    np.testing.assert_allclose(cut, ref, rtol=1e-12, atol=1e-12 * sigma)
    np.testing.assert_array_equal(cut, gauss_markov(sigma, tau, dt, np.random.default_rng(4)).block(20000))


def test_flicker_equals_its_branches_through_lfilter():
    b, tau_min, tau_max, dt = 1e-5, 0.1, 1e3, 1e-3
    fl = Flicker(b, tau_min, tau_max, dt, np.random.default_rng(8))
    start = fl.state.copy()                          # the branches' stationary draw (n, 3)
    p, c = flicker_design(b, tau_min, tau_max, dt)
    rng = np.random.default_rng(8)
    rng.standard_normal((p.size, 3))                 # the stationary draw comes first from the stream
    w = rng.standard_normal((20000, 3))
    phi, u = np.exp(-p * dt), -np.expm1(-p * dt) / p / math.sqrt(dt)
    ref = sum(c[i] * signal.lfilter([u[i]], [1.0, -phi[i]], w, axis=0, zi=phi[i] * start[i][None, :])[0]
              for i in range(p.size))
    np.testing.assert_allclose(pieces(fl.block, 20000), ref, rtol=0, atol=1e-12 * np.max(np.abs(ref)))


def test_truth_and_imu_run_needs_neither_numba_nor_scipy_signal(tmp_path):
    code = ("import sys, simkit\n"
            "simkit.run({'scenario': {'name': 'x', 'start': '2026-01-01T00:00:00Z', 'duration_s': 2.0},\n"
            "            'trajectory': {'rate_hz': 1000.0, 'origin': {'lat_deg': 34.0, 'lon_deg': 108.0, 'height_m': 400.0},\n"
            "                           'segment': [{'kind': 'cruise', 'duration_s': 2.0}]},\n"
            f"            'imu': {{'preset': 'stim300'}}}}, out={str(tmp_path / 'x.h5')!r})\n"
            "print(sorted(m for m in ('numba', 'scipy.signal', 'scipy.interpolate', 'simkit.gnss') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
