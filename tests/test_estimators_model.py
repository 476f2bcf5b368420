"""The error model against the nonlinear mechanisation it linearises (finite differences of two strapdown runs,
the strapdown itself being checked against the analytic truth), the measurement Jacobians against finite
differences of the exact measurement functions, and the alignments against closed forms."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from simkit import earth
from simkit.estimators import motion_alignment, static_alignment
from simkit.estimators import model, nav
from simkit.frames import attitude_from_euler, euler_from_attitude

DT = 0.01


def _run(c, v, pos, w, f, bg, ba):
    """Strapdown over constant rates ``w``, ``f`` (body) with sensor errors bg, ba added to the readings."""
    v_prev = v.copy()
    for _ in range(100):
        phi = (w + bg) * DT
        dvb = (f + ba) * DT + 0.5 * np.cross(phi, (f + ba) * DT)
        c, v_new, pos, fn = nav.step(c, v, pos, v_prev, phi, dvb, DT)
        v_prev, v = v, v_new
    return c, v, pos


def test_transition_matrix_predicts_the_nonlinear_error_growth():
    # a turning, climbing aircraft at 45 N: 1 s of constant body rate and specific force
    c0 = attitude_from_euler(0.1, 0.3, 1.0).as_matrix()
    v0, p0 = np.array([150.0, 120.0, 10.0]), np.array([np.radians(45.0), 0.3, 3000.0])
    w, f = np.array([0.02, -0.05, 0.1]), np.array([0.5, 2.0, 11.0])
    dx = np.array([2e-5, -1e-5, 3e-5, 1e-3, -2e-3, 1e-3, 2e-7, -1e-7, 1.5, 2e-6, -1e-6, 3e-6, 1e-3, 2e-3, -1e-3])
    ref = _run(c0, v0, p0, w, f, np.zeros(3), np.zeros(3))
    pert = _run((np.eye(3) - nav.skew(dx[0:3])) @ c0, v0 + dx[3:6], p0 + dx[6:9], w, f, dx[9:12], dx[12:15])
    phi_end = -Rotation.from_matrix(pert[0] @ ref[0].T).as_rotvec()
    actual = np.concatenate([phi_end, pert[1] - ref[1], pert[2] - ref[2]])
    # Phi over the interval along the reference trajectory (F frozen every 0.1 s, as the filter does)
    big = np.eye(15)
    c, v, pos, v_prev = c0, v0, p0, v0.copy()
    for _ in range(10):
        c_s, v_s, p_s = c, v, pos
        for _ in range(10):
            phi = w * DT
            c, v_new, pos, fn = nav.step(c, v, pos, v_prev, phi, f * DT + 0.5 * np.cross(phi, f * DT), DT)
            v_prev, v = v, v_new
        phim, _ = model.discretise(model.system_matrix(c, v, pos, c @ f, 15), np.zeros(15), 0.1)
        big = phim @ big
    predicted = (big @ dx)[:9]
    # per block (attitude, velocity, latitude/longitude, height): within 1 % of the block's largest response; the
    # residue is F frozen over 0.1 s and second-order terms (measured: 0.3 % velocity, 2e-4 attitude)
    for blk in (slice(0, 3), slice(3, 6), slice(6, 8), slice(8, 9)):
        tol = 0.01 * np.abs(actual[blk]).max()
        assert np.all(np.abs(predicted[blk] - actual[blk]) < tol), np.c_[predicted, actual]


def test_antenna_jacobian_is_the_derivative_of_the_lever_arm_geometry():
    c = attitude_from_euler(0.2, -0.4, 2.0).as_matrix()
    v, pos = np.array([80.0, -30.0, 5.0]), np.array([0.6, 1.9, 1200.0])
    lever, w = np.array([1.0, 2.0, 3.0]), np.array([0.3, -0.2, 0.5])
    pred0, h = model.antenna_rows(c, v, pos, lever, w, 18, 15)
    steps = [1e-6] * 3 + [1e-3] * 3 + [1e-8, 1e-8, 1e-2] + [0.0] * 6 + [1e-3] * 3
    for j, d in enumerate(steps):
        if d == 0.0:
            assert np.all(h[:, j] == 0.0)
            continue
        x = np.zeros(18)
        x[j] = d
        cc, vv, pp, ll = (np.eye(3) - nav.skew(x[0:3])) @ c, v + x[3:6], pos + x[6:9], lever + x[15:18]
        numeric = (model.antenna_rows(cc, vv, pp, ll, w, 18, 15)[0] - pred0) / d
        # the model leaves out the attitude dependence of w_nb^b through C^T w_in^n (w_in ~ 1e-4 of w_ib here)
        assert np.allclose(h[:, j], numeric, rtol=1e-3, atol=5e-4 * np.abs(numeric).max() + 1e-12), j


def test_euler_kernel_is_simkit_frames_and_its_jacobian_matches_finite_differences():
    rng = np.random.default_rng(3)
    for _ in range(20):
        e = np.array([rng.uniform(-1.2, 1.2), rng.uniform(-3, 3), rng.uniform(0, 2 * np.pi)])
        c = attitude_from_euler(*e).as_matrix()
        ours, h = model.attitude_rows(c, 15)
        ref = euler_from_attitude(Rotation.from_matrix(c))
        assert np.allclose(model.wrap(ours - ref), 0.0, atol=1e-12)
        d = 1e-7
        for j in range(3):
            u = np.zeros(3)
            u[j] = d
            num = model.wrap(model.euler((np.eye(3) - nav.skew(u)) @ c) - ours) / d
            assert np.allclose(h[:, j], num, atol=1e-5)


def test_static_alignment_is_exact_on_error_free_data():
    lat = np.radians(34.2)
    truth = np.array([0.03, -0.02, np.radians(123.0)])
    rot = attitude_from_euler(*truth)
    w_b = rot.inv().apply(earth.earth_rate_enu(lat))
    f_b = rot.inv().apply([0.0, 0.0, earth.normal_gravity(lat, 400.0)])
    euler, sigma = static_alignment(np.tile(w_b, (100, 1)), np.tile(f_b, (100, 1)), lat,
                                    gyro_bias_sigma=np.radians(4.0) / 3600)
    assert np.allclose(euler, truth, atol=1e-12)
    # a 4 deg/h gyro against 12.44 deg/h of horizontal Earth rate at 34.2 N: atan(4 / 12.44) = 17.8 deg
    assert np.degrees(sigma) == pytest.approx(17.8, abs=0.1)


def test_motion_alignment_follows_the_velocity():
    e = motion_alignment([100.0, 100.0, 10.0])
    assert np.degrees(e[2]) == pytest.approx(45.0) and e[0] == pytest.approx(np.arctan2(10, 100 * np.sqrt(2)))
