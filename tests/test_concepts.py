"""One owner per small concept: angle wrap, skew matrix, Euler Jacobian, Sagnac rotation, single-point positioning,
the DD float solution and the physical constants are defined once (a lower layer) and checked against closed
forms."""
import ast
from pathlib import Path

import numpy as np

from simkit import frames
from simkit.estimators import model, nav

PKG = Path(__file__).resolve().parents[1] / "simkit"

# concept -> the modules allowed to define it; nav.skew is the compiled one-vector form the filter kernels call
OWNERS = {"wrap": {"frames.py"}, "wrap_2pi": {"frames.py"}, "skew": {"frames.py", "estimators/nav.py"}, "euler_jacobian": {"frames.py"},
          "sagnac_rotate": {"constellation/geometry.py"}, "dd_operator": {"gnss/differencing.py"},
          "dd_matrix": {"gnss/differencing.py"}, "spp": {"gnss/spp.py"}, "dd_float": {"gnss/differencing.py"},
          "symmetric": {"gnss/differencing.py"}, "systems_of": {"gnss/differencing.py"},
          "_gauss_newton": set(), "truth_at": {"io/readers.py"}, "slerp": {"quat.py"}}
CONSTANTS = {"C_LIGHT", "OMEGA_E", "G0", "GM", "A", "F", "E2"}
WGS84_OMEGA_E = 7.292115e-5  # rad/s, NIMA TR8350.2 table 3.1
C = 299792458.0              # m/s, exact by the SI definition of the metre


def _modules():
    for path in sorted(PKG.rglob("*.py")):
        yield path.relative_to(PKG).as_posix(), ast.parse(path.read_text())


def test_each_small_concept_is_defined_by_its_owner_only():
    found = {name: set() for name in OWNERS}
    for rel, tree in _modules():
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef) and node.name in OWNERS:
                found[node.name].add(rel)
    assert found == OWNERS


def test_physical_constants_are_assigned_only_in_earth():
    offenders = []
    for rel, tree in _modules():
        for node in tree.body:
            if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant) and rel != "earth.py":
                offenders += [f"{rel}: {t.id}" for t in node.targets if isinstance(t, ast.Name) and t.id in CONSTANTS]
    assert not offenders


def test_wrap_gives_the_angle_in_minus_pi_to_pi_for_numpy_and_compiled_callers():
    x = np.linspace(-np.pi, np.pi, 101)[:-1]
    for k in (-3, -1, 0, 2, 5):
        assert np.allclose(frames.wrap(x + 2 * np.pi * k), x, rtol=0, atol=1e-13)
    assert frames.wrap(np.pi) == -np.pi and frames.wrap(3.0) == 3.0
    assert model.wrap.py_func is frames.wrap  # the filter's innovations (loop.py) compile the same definition


def test_skew_is_the_cross_product_and_the_kernel_form_agrees():
    rng = np.random.default_rng(1)
    v, x = rng.normal(size=(4, 5, 3)), rng.normal(size=(4, 5, 3))
    assert np.allclose(np.einsum("abij,abj->abi", frames.skew(v), x), np.cross(v, x), rtol=0, atol=1e-14)
    assert all(np.array_equal(frames.skew(u), nav.skew(u)) for u in v[0])


def test_euler_jacobian_at_level_attitude_is_the_closed_form():
    """Level, heading h: a rotation phi (E, N, U) moves pitch by phi_e cos h - phi_n sin h, roll by
    phi_e sin h + phi_n cos h and heading by -phi_u (body y forward, x right, heading clockwise from north)."""
    h = np.array([0.3, 2.0, 4.5, 6.2])
    J = frames.euler_jacobian(frames.attitude_from_euler(0 * h, 0 * h, h))
    c, s, z = np.cos(h), np.sin(h), np.zeros_like(h)
    ref = np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, z - 1], -1)], -2)
    assert np.allclose(J, ref, rtol=0, atol=1e-8)


def test_sagnac_rotation_is_the_wgs84_earth_rate_over_the_light_time():
    from simkit.attitude.geometry import sagnac_rotate  # the attitude solvers' import path

    rx = frames.lla_to_ecef(np.radians([34.0, -20.0]), np.radians([108.0, 10.0]), np.array([400.0, 0.0]))
    sat = np.array([[[15.6e6, 9.0e6, 19.0e6], [-3.0e6, 25.0e6, 7.0e6]]] * 2) + rx[:, None, :] * 0.0
    out = sagnac_rotate(sat, rx)
    angle = np.arctan2(sat[..., 0] * out[..., 1] - sat[..., 1] * out[..., 0],
                       sat[..., 0] * out[..., 0] + sat[..., 1] * out[..., 1])
    tau = np.linalg.norm(sat - rx[:, None, :], axis=-1) / C
    assert np.allclose(-angle, WGS84_OMEGA_E * tau, rtol=1e-10, atol=0)
    assert np.array_equal(out[..., 2], sat[..., 2])


def test_lines_of_sight_enu_are_the_local_vertical_and_horizon_directions():
    """A satellite on the receiver's geodetic normal is at the zenith (E, N, U = 0, 0, 1); one on the meridian
    plane's tangent to the north is on the horizon due north (0, 1, 0)."""
    from simkit.constellation.geometry import lines_of_sight_enu

    lat, lon, h = np.radians([30.0, -45.0]), np.radians([100.0, 5.0]), np.array([50.0, 1000.0])
    rx = frames.lla_to_ecef(lat, lon, h)
    up = frames.lla_to_ecef(lat, lon, h + 2.0e7) - rx
    north = np.stack([-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)], -1) * 2.0e7
    e, el = lines_of_sight_enu(rx, rx[:, None, :] + np.stack([up, north], 1))
    assert np.allclose(e, [[0, 0, 1], [0, 1, 0]], rtol=0, atol=1e-9)
    assert np.allclose(el, [[np.pi / 2, 0.0]] * 2, rtol=0, atol=1e-4)  # arcsin near 1: 1e-9 in e is 4e-5 rad


def test_lever_arm_points_of_a_body_turning_with_the_earth_are_at_rest_in_ecef():
    """A level body facing north (heading 0) at rest on the Earth senses w_ie only: its forward lever arm (0, l, 0)
    lies l metres due north and does not move in ECEF; adding a yaw rate w about up moves it at w l due west."""
    from simkit import earth

    lat, lon = np.radians([45.0, -10.0]), np.radians([7.0, 120.0])
    pos = frames.lla_to_ecef(lat, lon, np.zeros(2))
    q = frames.quat_from_euler(np.zeros(2), np.zeros(2), np.zeros(2))
    w_ie_b = earth.earth_rate_enu(lat)  # body axes = E, N, U at heading 0
    lever = np.array([[0.0, 2.0, 0.0]])
    p, v, _ = frames.lever_arm_ecef(pos, np.zeros((2, 3)), q, w_ie_b, lever)
    north = frames.enu_to_ecef_vec(np.array([0.0, 1.0, 0.0]), lat, lon)
    west = frames.enu_to_ecef_vec(np.array([-1.0, 0.0, 0.0]), lat, lon)
    assert np.allclose(p[:, 0] - pos, 2.0 * north, rtol=0, atol=1e-9)
    assert np.allclose(v[:, 0], 0.0, rtol=0, atol=1e-15)
    _, v, _ = frames.lever_arm_ecef(pos, np.zeros((2, 3)), q, w_ie_b + [0.0, 0.0, 0.1], lever)
    assert np.allclose(v[:, 0], 0.2 * west, rtol=0, atol=1e-15)


def test_dd_operator_from_any_reference_antenna_equals_the_double_differences():
    from simkit.gnss.differencing import dd_operator, double_difference

    rng = np.random.default_rng(4)
    x = rng.normal(size=(1, 3, 6))
    ref = np.array([[2, 2, 2, 5, 5, 5]])  # two systems, references 2 and 5
    valid = np.array([True, True, True, False, True, True])
    for ref_antenna in (0, 1, 2):
        D, ant, sat = dd_operator(ref[0], valid, 3, ref_antenna)
        dd = double_difference(x, ref, ref_antenna)[0]  # (A-1, S), antennas in order without the reference
        rows = np.searchsorted(np.delete(np.arange(3), ref_antenna), ant)
        assert np.allclose(D @ x[0].reshape(-1), dd[rows, sat], rtol=0, atol=1e-14)
        assert sorted(set(sat)) == [0, 1, 4] and np.array_equal(ant, np.repeat(np.delete(np.arange(3), ref_antenna), 3))


def test_the_dd_float_solution_of_equal_sigmas_is_the_joint_least_squares_of_carrier_and_code():
    """gnss.differencing.float_solution goes through dd_float (code-only baseline); the joint least squares of
    carrier and code with free ambiguities (normal equations written out here) gives the same estimate."""
    from simkit.gnss.differencing import _between_satellite_cofactor, float_solution
    rng = np.random.default_rng(4)
    T, r, n, lam, sp, sc = 3, 2, 6, 0.19, 0.003, 0.3
    G = rng.normal(size=(T, n, 3))
    car, code = rng.normal(size=(T, r, n)) * 10, rng.normal(size=(T, r, n))
    fs = float_solution(G, car, code, lam, sp, sc)
    Ci = np.linalg.inv(np.kron(np.eye(r) + np.ones((r, r)), _between_satellite_cofactor(n)))
    for t in range(T):
        Gr = np.kron(np.eye(r), G[t])
        A = np.block([[lam * np.eye(r * n), Gr], [np.zeros((r * n, r * n)), Gr]])
        W = np.block([[Ci / sp**2, np.zeros_like(Ci)], [np.zeros_like(Ci), Ci / sc**2]])
        y = np.concatenate([lam * car[t].ravel(), code[t].ravel()])
        Q = np.linalg.inv(A.T @ W @ A)
        x = np.linalg.solve(A.T @ W @ A, A.T @ W @ y)
        assert np.allclose(fs.a_hat[t], x[:r * n], rtol=0, atol=1e-7)
        assert np.allclose(fs.b_hat[t], x[r * n:], rtol=0, atol=1e-8)
        assert np.allclose(fs.Qa[t], Q[:r * n, :r * n], rtol=1e-7, atol=0)
        assert np.allclose(fs.Qb[t], Q[r * n:, r * n:], rtol=1e-7, atol=0)
        assert np.allclose(fs.Qba[t], Q[r * n:, :r * n], rtol=1e-7, atol=1e-12)


def test_truth_at_interpolates_attitude_as_scipy_slerp_and_returns_the_samples_at_their_epochs():
    from scipy.spatial.transform import Rotation, Slerp

    from simkit.io import Truth, truth_at
    rng = np.random.default_rng(7)
    t = np.arange(6.0)
    q = Rotation.from_rotvec(rng.normal(size=(6, 3)) * 0.5).as_quat()
    pos = np.array([6378137.0, 0, 0]) + rng.normal(size=(6, 3))
    truth = Truth(t, pos, rng.normal(size=(6, 3)), q, rng.normal(size=(6, 3)))
    tk = rng.uniform(0, 5, 40)
    got = truth_at(truth, tk).quat_nb
    want = Slerp(t, Rotation.from_quat(q))(tk).as_quat()
    assert np.allclose(got * np.sign(got[:, 3:]), want * np.sign(want[:, 3:]), rtol=0, atol=1e-12)
    at = truth_at(truth, t[:-1])
    assert np.array_equal(at.pos_ecef, pos[:-1]) and np.array_equal(at.omega_ib_b, truth.omega_ib_b[:-1])
    assert np.allclose(at.quat_nb, q[:-1], rtol=0, atol=1e-15)
