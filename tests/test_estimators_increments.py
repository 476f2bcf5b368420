"""IMU increments in the estimators (issue 19, defect 1).

Authorities: closed forms of a steady roll (constant body rate, constant specific force in the navigation frame,
so the exact body-frame increments are sin / cos integrals), a quadratic rate (exact integrals), and the file's
truth for the filters; the two IMU outputs of one simulated flight describe the same motion, so a filter must be
at least as exact on increments as on rates."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from simkit.estimators.increments import from_increments, from_rates

T = 0.01                               # s, 100 Hz as in high_dynamic
ROLL = np.array([0.0, np.radians(220.0), 0.0])  # rad/s about body y (forward): high_dynamic's roll rate
F0 = np.array([1.0, 3.0, 9.8])         # m/s^2, specific force fixed in the frame of t = 0


def _steady_roll(n=12):
    """t (n,), gyro and accel samples, and the exact increments over (t[k-1], t[k]] of a steady roll: the body
    turns at ROLL, so f^b(t) = R(ROLL t)^T F0 = F0_par + cos(W t) F0_perp - sin(W t) u x F0_perp."""
    t = np.arange(n) * T
    w = np.linalg.norm(ROLL)
    u = ROLL / w
    par = u * (u @ F0)
    perp = F0 - par

    def integral(t0, t1):
        return (par * (t1 - t0) + (np.sin(w * t1) - np.sin(w * t0)) / w * perp
                + (np.cos(w * t1) - np.cos(w * t0)) / w * np.cross(u, perp))

    dvel = np.array([integral(tk - T, tk) for tk in t])
    accel = Rotation.from_rotvec(np.outer(t, ROLL)).inv().apply(F0)
    return t, np.tile(ROLL, (n, 1)), accel, np.tile(ROLL * T, (n, 1)), dvel


@pytest.mark.parametrize("output", ["rates", "increments"])
def test_steady_roll_velocity_increments_are_exact(output):
    # the velocity increment of interval k in the body axes at t[k-1] is R(ROLL t[k-1])^T F0 T exactly (F0 fixed in
    # the frame of t = 0). Without the second-order rotation term alpha x (alpha x dv) / 6 the compensation is off by
    # T^3/6 |w|^2 |f_perp| = 12 um/s per interval (rates, halved by their linear model) and 24 um/s (increments).
    # The models' next term is |w|^3 |f| T^4 / 24 = 2.4e-7 m/s: allow 1e-6 (the first interval has no history)
    t, gyro, accel, dtheta, dvel = _steady_roll()
    comp = from_rates(t, gyro, accel) if output == "rates" else from_increments(t, dtheta, dvel)
    expect = Rotation.from_rotvec(np.outer(t[:-1], ROLL)).inv().apply(F0) * T
    assert np.abs(comp.dvb - expect)[1:].max() < 1e-6
    assert np.abs(comp.phi - ROLL * T).max() < 1e-15


@pytest.mark.parametrize("output", ["rates", "increments"])
def test_lever_arm_rate_is_the_rate_at_the_sample_time(output):
    # w(t) = w0 + w1 t + w2 t^2: increments dtheta[k] = its exact integral over (t[k-1], t[k]]. The rate at t[k]
    # (what the lever-arm velocity at a GNSS epoch needs) is w(t[k]); the interval mean dtheta / T is w near
    # t[k] - T/2, 4 mrad/s off here. Both models are exact for a quadratic rate once three intervals are in.
    w0, w1, w2 = np.array([0.1, -0.2, 0.3]), np.array([0.8, 2.0, -1.0]), np.array([3.0, -4.0, 5.0])
    t = np.arange(10) * T
    rate = w0 + np.outer(t, w1) + np.outer(t**2, w2)
    cum = np.outer(t, w0) + np.outer(t**2, w1) / 2 + np.outer(t**3, w2) / 3
    dtheta = np.vstack([rate[0] * T, np.diff(cum, axis=0)])
    f = np.zeros_like(rate)
    comp = from_rates(t, rate, f) if output == "rates" else from_increments(t, dtheta, f * T)
    np.testing.assert_allclose(comp.w_ib[3:], rate[3:], rtol=0, atol=1e-12)
