"""Two-ray multipath errors against the classic envelopes of a coherent early-late DLL (Braasch, in Parkinson &
Spilker 1996, ch. 14; the in-phase / out-of-phase bounds) and the closed-form carrier phase error."""
import numpy as np
import pytest

from simkit.gnss import tworay


@pytest.mark.parametrize("alpha, spacing", [(0.5, 0.5), (0.3, 1.0), (0.8, 0.1)])
def test_in_phase_and_out_of_phase_envelopes(alpha, spacing):
    h = spacing / 2
    d = np.linspace(1e-3, 1.0 + h + 0.2, 400)
    up = tworay.dll_error_chips(alpha, d, 0.0, spacing)
    down = tworay.dll_error_chips(alpha, d, np.pi, spacing)
    ramp_up, ramp_down = d <= (1 + alpha) * h, d <= (1 - alpha) * h
    np.testing.assert_allclose(up[ramp_up], alpha * d[ramp_up] / (1 + alpha), atol=1e-12)
    np.testing.assert_allclose(down[ramp_down], -alpha * d[ramp_down] / (1 - alpha), atol=1e-12)
    flat_up = (d >= (1 + alpha) * h) & (d <= 1 - h)
    flat_down = (d >= (1 - alpha) * h) & (d <= 1 - h - alpha * h)
    np.testing.assert_allclose(up[flat_up], alpha * h, atol=1e-12)
    np.testing.assert_allclose(down[flat_down], -alpha * h, atol=1e-12)
    far = d > 1 + h
    assert (np.abs(up[far]) < 1e-12).all() and (np.abs(down[far]) < 1e-12).all()


def test_error_bounded_by_the_envelope_for_any_phase():
    rng = np.random.default_rng(4)
    alpha, delta = rng.uniform(0.01, 0.95, 20000), rng.uniform(0, 2, 20000)
    theta, spacing = rng.uniform(-np.pi, np.pi, 20000), 0.2
    e = tworay.dll_error_chips(alpha, delta, theta, spacing)
    assert np.isfinite(e).all()
    assert (np.abs(e) <= alpha * spacing / 2 + 1e-12).all()
    # the in-phase and out-of-phase cases bound every other phase at the same delay and amplitude
    hi = tworay.dll_error_chips(alpha, delta, 0.0, spacing)
    lo = tworay.dll_error_chips(alpha, delta, np.pi, spacing)
    assert ((e <= hi + 1e-12) & (e >= lo - 1e-12)).all()


def test_carrier_error_closed_form_bound_and_rate():
    alpha = np.array([0.2, 0.5, 0.9])[:, None]
    theta = np.linspace(-np.pi, np.pi, 3601)[None]
    psi = tworay.carrier_phase_error(alpha, theta)
    np.testing.assert_allclose(np.abs(psi).max(axis=1), np.arcsin(alpha[:, 0]), rtol=1e-6)
    np.testing.assert_allclose(tworay.carrier_phase_error(0.5, np.pi / 2), np.arctan(0.5))
    step = 1e-6
    numeric = (tworay.carrier_phase_error(alpha, theta + step) - tworay.carrier_phase_error(alpha, theta - step)) \
        / (2 * step)
    np.testing.assert_allclose(tworay.carrier_phase_error_rate(alpha, theta, 1.0), numeric, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(tworay.amplitude_gain_db(0.5, 0.0), 20 * np.log10(1.5))
