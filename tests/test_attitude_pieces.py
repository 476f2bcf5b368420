"""simkit.attitude pieces on arrays, against closed forms and independent constructions (no file)."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from simkit import ambiguity as amb
from simkit.attitude import (AttitudeInputError, FixPolicy, Observations, badshah_eq10, euler_atdop, float_solution,
                             phi_covariance, resolve, single_baseline, wahba_svd)
from simkit.attitude.tdcp import tdcp_velocity
from simkit.attitude.wahba import propagated_covariance, wahba_wls
from simkit.frames import attitude_from_euler, euler_from_attitude
from simkit.gnss import differencing

LAM = 0.19029367  # GPS L1 wavelength, m
F = np.array([[0.0, 1.2], [1.5, 0.0], [0.0, 0.1]])  # body baselines (3, 2): forward and right, m


def _sky(rng, m, s, min_el=15.0):
    az = rng.uniform(0, 2 * np.pi, (1, s)) + np.linspace(0, 0.01, m)[:, None]
    el = np.radians(rng.uniform(min_el, 85.0, (1, s))) + np.zeros((m, 1))
    los = np.stack([np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)], -1)
    return los, el


def _obs(rng, R, m=40, s=8, sig_phi=0.002, sig_p=0.2):
    """Synthetic single-signal observations for antennas at R @ [0, f_1, f_2] (ENU), with true integers N."""
    los, el = _sky(rng, m, s)
    pos = np.concatenate([np.zeros((m, 1, 3)), np.broadcast_to((R @ F).T, (m, 2, 3))], axis=1)  # (M, A, 3)
    rng_m = -np.einsum("msi,mai->mas", los, pos) + 2.0e7
    N = rng.integers(-1000, 1000, (1, 3, s)) + np.zeros((m, 1, 1), int)
    carrier = (rng_m + sig_phi * rng.standard_normal(rng_m.shape)) / LAM + N
    code = rng_m + sig_p * rng.standard_normal(rng_m.shape)
    ones = np.ones((1,) + rng_m.shape)
    obs = Observations(carrier[None], code[None], sig_phi ** 2 * ones, sig_p ** 2 * ones, np.array([LAM]), los,
                       el, np.array([f"G{i + 1:02d}" for i in range(s)]))
    return obs, N


def test_wahba_and_badshah_recover_a_rotation_exactly():
    R = attitude_from_euler(np.radians([5.0, -3.0]), np.radians([10.0, 2.0]), np.radians([30.0, 250.0]))
    b = R.as_matrix() @ F
    assert np.allclose(wahba_svd(b, F), R.as_matrix(), atol=1e-12)
    assert np.allclose(badshah_eq10(b, F), R.as_matrix(), atol=1e-12)


def test_single_baseline_heading_and_pitch_closed_form():
    pitch, heading = np.radians([7.0, -12.0]), np.radians([40.0, 300.0])
    R = attitude_from_euler(pitch, np.radians([25.0, -30.0]), heading).as_matrix()  # roll does not move y
    f = np.array([0.0, 2.0, 0.0])
    p, h, cov = single_baseline(R @ f, np.repeat(np.eye(3)[None] * 1e-6, 2, 0), f)
    assert np.allclose(p, pitch, atol=1e-12) and np.allclose(h, heading, atol=1e-12)
    # isotropic 1 mm on a 2 m baseline: heading sd = 1 mm / horizontal length, pitch sd = 1 mm / length
    assert np.allclose(np.sqrt(cov[:, 0, 0]), 1e-3 / 2.0, rtol=1e-9)
    assert np.allclose(np.sqrt(cov[:, 1, 1]), 1e-3 / (2.0 * np.cos(pitch)), rtol=1e-9)


def test_attitude_covariances_match_monte_carlo():
    rng = np.random.default_rng(1)
    R = attitude_from_euler(0.05, -0.1, 1.0).as_matrix()
    A = rng.standard_normal((6, 6))
    Qb = (A @ A.T + 6 * np.eye(6)) * 1e-6  # correlated mm-level baseline errors
    n = 4000
    e = rng.standard_normal((n, 6)) @ np.linalg.cholesky(Qb).T
    b = (R @ F)[None] + e.reshape(n, 2, 3).transpose(0, 2, 1)
    Qs = np.broadcast_to(Qb, (n, 6, 6))
    w = np.ones((n, 2))
    for est, P in ((lambda x: wahba_wls(x, F, Qs[: len(x)]), phi_covariance(R[None], F, Qb[None])[0]),
                   (lambda x: wahba_svd(x, F, w[: len(x)]),
                    propagated_covariance(lambda x: wahba_svd(x, F, w[:1]), (R @ F)[None], Qb[None])[0]),
                   (lambda x: badshah_eq10(x, F),
                    propagated_covariance(lambda x: badshah_eq10(x, F), (R @ F)[None], Qb[None])[0])):
        phi = Rotation.from_matrix(est(b) @ R.T).as_rotvec()
        emp = np.cov(phi.T)
        assert np.allclose(np.sqrt(np.diag(emp)), np.sqrt(np.diag(P)), rtol=0.06)


def test_atdop_equals_wang_eq22_gramian():
    """Wang 2018 eq 22: three antennas, b1 = l1 forward, b2 = l2 right, body aligned with ENU."""
    rng = np.random.default_rng(2)
    l1, l2 = 3.965, 9.445
    Fw = np.array([[0.0, l2], [l1, 0.0], [0.0, 0.0]])
    s = rng.standard_normal((6, 3))  # DD line-of-sight rows s^i (any)
    sx, sy, sz = s.T
    L = np.array([[l1 ** 2 * (sz ** 2).sum(), 0, -l1 ** 2 * (sz * sx).sum()],
                  [0, l2 ** 2 * (sz ** 2).sum(), -l2 ** 2 * (sz * sy).sum()],
                  [-l1 ** 2 * (sz * sx).sum(), -l2 ** 2 * (sz * sy).sum(),
                   l1 ** 2 * (sx ** 2).sum() + l2 ** 2 * (sy ** 2).sum()]])
    ours = euler_atdop(np.eye(3)[None], Fw, s[None])[0]
    assert np.allclose(ours, np.sqrt(np.diag(np.linalg.inv(L))), rtol=1e-6)


def test_float_solution_is_exact_without_noise_and_its_dd_rows_match_gnss_differencing():
    rng = np.random.default_rng(3)
    R = attitude_from_euler(0.02, 0.03, 2.0).as_matrix()
    obs, N = _obs(rng, R, m=5, sig_phi=0.0, sig_p=0.0)
    obs = Observations(obs.carrier, obs.code, obs.var_carrier + 1e-6, obs.var_code + 1e-2, obs.wavelength,
                       obs.los, obs.elevation, obs.sat_ids)
    (grp,) = float_solution(obs)
    ref = differencing.reference_satellites(obs.elevation, np.ones(obs.elevation.shape, bool), obs.sat_ids)
    D, ant, sat = differencing.dd_operator(ref[0], np.ones(8, bool), 3)
    truth = N.reshape(5, -1) @ D.T
    order = np.lexsort((sat, ant))
    assert np.array_equal(np.round(grp.a_hat), truth[:, order])
    assert np.allclose(grp.a_hat, truth[:, order], atol=1e-6)
    assert np.allclose(grp.b_hat.reshape(5, 2, 3), np.broadcast_to((R @ F).T, (5, 2, 3)), atol=1e-6)
    # Qphi = D diag(sigma^2) D' of the independent construction in simkit.gnss.differencing
    Q, _, _ = differencing.dd_covariance(np.full((3, 8), 1e-3), ref[0], np.ones(8, bool))
    assert np.allclose(grp.Qphi[0], Q[np.ix_(order, order)], rtol=1e-12)


@pytest.mark.parametrize("method", ["lambda", "clambda", "mclambda"])
def test_resolve_fixes_the_true_integers(method):
    rng = np.random.default_rng(4)
    R = attitude_from_euler(0.01, -0.02, 0.7).as_matrix()
    obs, N = _obs(rng, R, m=20)
    (grp,) = float_solution(obs)
    res = resolve(grp, method, F, FixPolicy(validation="ratio"))  # the searches; validation pf: see the test below
    ref = differencing.reference_satellites(obs.elevation, np.ones(obs.elevation.shape, bool), obs.sat_ids)
    D, ant, sat = differencing.dd_operator(ref[0], np.ones(8, bool), 3)
    truth = (N.reshape(20, -1) @ D.T)[:, np.lexsort((sat, ant))]
    ok = res.accepted
    assert ok.mean() > 0.9 and np.array_equal(res.z[ok], truth[ok])
    assert np.all(res.success_rate > 0.99)
    if method == "mclambda":
        assert np.allclose(res.rotation[ok], R, atol=0.03)  # DD carrier 4 mm on 1.2-1.5 m baselines


def test_ratio_stop_keeps_the_best_and_bounds_the_second():
    rng = np.random.default_rng(5)
    obs, _ = _obs(rng, attitude_from_euler(0.0, 0.0, 1.0).as_matrix(), m=6, s=6)
    (g,) = float_solution(obs)
    sl = slice(0, g.a_hat.shape[1] // 2)
    args = (g.a_hat[:, sl], g.Qa[:, sl, sl], g.b_hat[:, :3], g.Qb[:, :3, :3], g.Qba[:, :3, sl], 1.5)
    full = amb.baseline_constrained_ils(*args, n_cands=2)
    bnd = amb.baseline_constrained_ils(*args, n_cands=2, ratio_stop=3.0)
    assert np.array_equal(full.candidates[:, 0], bnd.candidates[:, 0])
    assert np.allclose(full.costs[:, 0], bnd.costs[:, 0])
    assert np.all(bnd.costs[:, 1] <= full.costs[:, 1] * (1 + 1e-12))
    assert np.all(bnd.costs[bnd.bounded, 1] >= 3.0 * bnd.costs[bnd.bounded, 0])
    assert set(bnd.status) <= {"bounded", "finished"}


def test_tdcp_recovers_velocity_and_rejects_a_slip():
    rng = np.random.default_rng(6)
    m, s = 11, 9
    sat0 = rng.standard_normal((s, 3))
    sat0 = 2.6e7 * sat0 / np.linalg.norm(sat0, axis=1, keepdims=True)
    sat0[:, 2] = np.abs(sat0[:, 2]) + 1e7  # all above a receiver near the north pole region
    t = np.arange(m, dtype=float)
    sat = sat0[None] + t[:, None, None] * rng.uniform(-3e3, 3e3, (1, s, 3))
    v = np.array([20.0, -5.0, 1.0])
    rec = np.array([1.0e6, 0.5e6, 6.2e6])[None] + t[:, None] * v
    from simkit.attitude.geometry import sagnac_rotate
    rho = np.linalg.norm(sagnac_rotate(sat, rec) - rec[:, None], axis=-1)
    phase = rho + 300.0 * t[:, None] + rng.integers(-99, 99, s) * LAM
    phase[6:, 3] += 7 * LAM  # a slip without an LLI flag
    usable = np.ones((m - 1, s), bool)
    vel, drift, used, rms = tdcp_velocity(phase, usable, sat, np.zeros((m, s)), rec, np.ones(m - 1))
    assert np.allclose(vel, v, atol=1e-6) and np.allclose(drift, 300.0, atol=1e-6)
    assert not used[5, 3] and used[[4, 6], 3].all()
    # a 5 m error in the approximate position costs |d e| x 5 m: below 1 mm/s for these satellite motions
    vel, *_ = tdcp_velocity(phase, usable, sat, np.zeros((m, s)), rec + 5.0 / np.sqrt(3), np.ones(m - 1))
    assert np.abs(vel - v).max() < 1e-3


def test_bad_input_names_the_argument():
    rng = np.random.default_rng(7)
    obs, _ = _obs(rng, np.eye(3), m=2)
    with pytest.raises(AttitudeInputError, match="code"):
        Observations(obs.carrier, obs.code[:, :1], obs.var_carrier, obs.var_code, obs.wavelength, obs.los,
                     obs.elevation, obs.sat_ids)
    (grp,) = float_solution(obs)
    with pytest.raises(AttitudeInputError, match="method"):
        resolve(grp, "ils", F)
    with pytest.raises(differencing.DifferencingInputError, match=r"expected \(M, A, S\)"):
        differencing.double_difference(np.zeros((3, 4)), np.zeros((3, 4), int))


def test_euler_round_trip_used_by_the_solution():
    e = np.radians([[3.0, -4.0, 350.0]])
    assert np.allclose(euler_from_attitude(attitude_from_euler(*e.T)), e)


def test_partial_fixing_fixes_true_integer_combinations_and_shrinks_the_baseline_covariance():
    rng = np.random.default_rng(8)
    obs, N = _obs(rng, attitude_from_euler(0.0, 0.0, 0.4).as_matrix(), m=30, s=6, sig_phi=0.003, sig_p=0.2)
    (grp,) = float_solution(obs)
    res = resolve(grp, "lambda", F, FixPolicy(ratio_threshold=1e9, partial_p0=0.99))  # no full fix passes
    ref = differencing.reference_satellites(obs.elevation, np.ones(obs.elevation.shape, bool), obs.sat_ids)
    D, ant, sat = differencing.dd_operator(ref[0], np.ones(6, bool), 3)
    truth = (N.reshape(30, -1) @ D.T)[:, np.lexsort((sat, ant))]
    part = np.flatnonzero(res.partial)
    assert part.size > 5 and not res.accepted.any()
    right = [np.array_equal(res.Z[i].T @ truth[i], res.z_check[i]) for i in part]
    assert np.mean(right) >= 0.9  # each subset was chosen with bootstrapped success rate >= 0.99
    for i in part:
        assert np.trace(res.Qb[i]) < np.trace(grp.Qb[i])


def _stacked_gls(obs, epochs, static):
    """Independent construction of the multi-epoch float: every epoch's DD carrier and code (simkit.gnss
    differencing) stacked in one weighted least squares with the ambiguities common and the baseline per epoch
    (or common, ``static``). Returns (a, Qa, b of the last epoch, Qb, Qba)."""
    ref = differencing.reference_satellites(obs.elevation, np.ones(obs.elevation.shape, bool), obs.sat_ids)
    n_e, lam = len(epochs), obs.wavelength[0]
    nb = 6 if static else 6 * n_e
    Hs, ys, Qs = [], [], []
    for j, m in enumerate(epochs):
        D, ant, sat = differencing.dd_operator(ref[m], np.ones(8, bool), 3)
        e = obs.los[m]
        G1 = -(e[sat] - e[ref[m][sat]])
        Gk = np.zeros((len(sat), 6))
        for k in (1, 2):
            Gk[ant == k, 3 * (k - 1):3 * k] = G1[ant == k]
        rn = len(sat)
        Hphi, Hp = np.zeros((rn, nb + rn)), np.zeros((rn, nb + rn))
        col = slice(0, 6) if static else slice(6 * j, 6 * j + 6)
        Hphi[:, col], Hp[:, col] = Gk, Gk
        Hphi[:, nb:] = lam * np.eye(rn)
        Hs += [Hphi, Hp]
        ys += [D @ (obs.carrier[0, m] * lam).ravel(), D @ obs.code[0, m].ravel()]
        Qs += [(D * obs.var_carrier[0, m].ravel()) @ D.T, (D * obs.var_code[0, m].ravel()) @ D.T]
    H, y = np.concatenate(Hs), np.concatenate(ys)
    W = np.linalg.inv(np.block([[Q if i == j else np.zeros((len(Q), len(P))) for j, P in enumerate(Qs)]
                                for i, Q in enumerate(Qs)]))
    P = np.linalg.inv(H.T @ W @ H)
    x = P @ H.T @ W @ y
    b = slice(nb - 6, nb)
    return x[nb:], P[nb:, nb:], x[b], P[b, b], P[b, nb:]


@pytest.mark.parametrize("static", [False, True])
def test_multi_epoch_float_equals_the_stacked_least_squares_and_resets_at_a_loss_of_lock(static):
    rng = np.random.default_rng(9)
    obs, _ = _obs(rng, attitude_from_euler(0.02, -0.01, 0.4).as_matrix(), m=7)
    lli = np.zeros(obs.carrier.shape, np.uint8)
    lli[0, 4, 2, 3] = 1  # antenna 2, satellite 3 at epoch 4: the window restarts there
    (single,) = float_solution(obs)
    (grp,) = float_solution(obs, epochs=3, static=static, lli=lli)
    for last, window in ((2, [0, 1, 2]), (3, [1, 2, 3]), (4, [4]), (6, [4, 5, 6])):
        a, Qa, b, Qb, Qba = _stacked_gls(obs, window, static)
        assert np.allclose(grp.a_hat[last], a, atol=1e-6) and np.allclose(grp.Qa[last], Qa, rtol=1e-7, atol=1e-12)
        assert np.allclose(grp.b_hat[last], b, atol=1e-8) and np.allclose(grp.Qb[last], Qb, rtol=1e-7, atol=1e-14)
        assert np.allclose(grp.Qba[last], Qba, rtol=1e-7, atol=1e-13)
    assert np.allclose(grp.a_hat[4], single.a_hat[4]) and np.allclose(grp.Qa[4], single.Qa[4])
    # three epochs of (nearly) the same geometry: about a third of the single-epoch ambiguity variance
    ratio = np.trace(grp.Qa[2]) / np.trace(single.Qa[2])
    assert 0.3 < ratio < 0.36 if not static else ratio < 0.34


def test_lever_arm_velocity_of_a_steady_turn_matches_the_closed_form():
    """A body turning at w about up (ENU fixed, no Earth rate in the differenced form): the lever arm's mean
    velocity over dt is the chord R(t1) l - R(t0) l over dt, of length 2 |l_h| sin(w dt / 2) / dt, and the
    instantaneous rate form gives |w| |l_h| (Earth rate removed)."""
    from simkit.attitude.lever import lever_velocity_differenced, lever_velocity_rate
    from simkit.earth import OMEGA_E
    w, dt, lever = 0.3, 0.5, np.array([1.0, 2.0, 3.0])
    h0 = np.radians([10.0, 200.0])
    R0 = attitude_from_euler(0 * h0, 0 * h0, h0).as_matrix()
    R1 = attitude_from_euler(0 * h0, 0 * h0, h0 + w * dt).as_matrix()
    E = np.broadcast_to(np.eye(3), (2, 3, 3))
    v, cov = lever_velocity_differenced(R0, R1, E, E, lever, np.full(2, dt))
    assert np.allclose(np.linalg.norm(v, axis=1), 2 * np.hypot(1, 2) * np.sin(w * dt / 2) / dt, rtol=1e-12)
    assert np.allclose(v[:, 2], 0) and np.all(cov == 0)
    lat = np.radians([34.2, 34.2])
    w_ie = OMEGA_E * np.array([0.0, np.cos(lat[0]), np.sin(lat[0])])
    w_ib = np.einsum("kji,j->ki", R0, w_ie) + np.array([0.0, 0.0, -w])  # heading clockwise: body rate -w about z
    P = np.broadcast_to(np.eye(3) * 1e-6, (2, 3, 3))
    vr, cr = lever_velocity_rate(R0, w_ib, lat, lever, P, np.broadcast_to(np.eye(3) * 1e-8, (2, 3, 3)))
    assert np.allclose(np.linalg.norm(vr, axis=1), w * np.hypot(1, 2), rtol=1e-12)
    mid = attitude_from_euler(0 * h0, 0 * h0, h0 + w * dt / 2).as_matrix()
    vm, _ = lever_velocity_rate(mid, np.einsum("kji,j->ki", mid, w_ie) + [0, 0, -w], lat, lever)
    assert np.allclose(vm * np.sin(w * dt / 2) / (w * dt / 2), v, atol=1e-12)  # chord vs arc at the midpoint
    # covariance: |v| sd of attitude 1 mrad in the plane of v and the rate noise 1e-4 rad/s x |l x axis|
    assert np.all(np.linalg.eigvalsh(cr) > 0)


def test_weighted_atdop_is_the_attitude_sd_of_the_weighted_fit_through_the_baselines():
    """Weighted ATDOP x s = the Euler sd of the carrier-only fit with the DD covariance Q, computed the other
    way round: fixed baselines Qb = (G' Q^-1 G)^-1 of the DD rows, then phi_covariance and euler_covariance.
    Unit weights (Q = s^2 I) give Wang's ATDOP."""
    from simkit.attitude.wahba import euler_covariance
    rng = np.random.default_rng(11)
    R = attitude_from_euler(0.05, -0.03, 2.2).as_matrix()[None]
    los, el = _sky(rng, 1, 8)
    G1 = -(los[:, 1:] - los[:, :1])  # (1, 7, 3) against satellite 0
    sig = 0.002 / np.sin(el[0])  # elevation-dependent undifferenced sd, m
    D = np.zeros((14, 3 * 8))  # DD of antennas (0, 1, 2) x 8 satellites, baseline-major
    for k in (1, 2):
        for i in range(7):
            for a, sa in ((k, 1), (0, -1)):
                D[(k - 1) * 7 + i, a * 8 + i + 1] += sa
                D[(k - 1) * 7 + i, a * 8] -= sa
    Q = (D * np.tile(sig ** 2, 3)) @ D.T
    Gb = np.kron(np.eye(2), G1[0])
    Qb = np.linalg.inv(Gb.T @ np.linalg.solve(Q, Gb))[None]
    sd = np.sqrt(np.diagonal(euler_covariance(R, phi_covariance(R, F, Qb)), axis1=1, axis2=2))
    s = np.sqrt(np.mean(np.diag(Q)))
    assert np.allclose(euler_atdop(R, F, G1, Q[None]) * s, sd, rtol=1e-6)
    assert np.allclose(euler_atdop(R, F, G1, np.eye(14)[None] * 3e-6), euler_atdop(R, F, G1), rtol=1e-9)
    assert not np.allclose(euler_atdop(R, F, G1, Q[None]), euler_atdop(R, F, G1), rtol=0.05)


def test_correlation_inflation_is_the_variance_of_the_mean_of_a_gauss_markov_sequence():
    from simkit.attitude.tight import correlation_inflation
    tau, dt, n = 30.0, 1.0, 40
    rho = np.exp(-dt / tau)
    C = rho ** np.abs(np.subtract.outer(np.arange(n), np.arange(n)))  # unit-variance AR(1) covariance
    assert np.isclose(correlation_inflation(tau, dt, n), C.sum() / n, rtol=1e-12)  # n Var(mean) / sigma^2
    assert np.isclose(correlation_inflation(tau, dt), (1 + rho) / (1 - rho), rtol=1e-12)
    assert correlation_inflation(0.0, dt) == 1.0


def test_ffrt_validation_bounds_and_options():
    """validation=ffrt: each epoch's mu equals the stand-alone calibration of its own Qa (same seed), epochs
    accepted exactly where best / 2nd <= mu; the success-rate bounds bracket the bootstrapped rate; ffrt is
    refused for the constrained solvers and unknown validations are named."""
    rng = np.random.default_rng(9)
    obs, _ = _obs(rng, attitude_from_euler(0.0, 0.0, 0.4).as_matrix(), m=8, s=5, sig_phi=0.003, sig_p=0.3)
    (grp,) = float_solution(obs)
    res = resolve(grp, "lambda", F, FixPolicy(validation="ffrt", pf=0.01, ffrt_samples=2000))
    assert np.all(res.sr_bounds[:, 0] <= res.sr_bounds[:, 1] + 1e-12)
    assert np.all(res.sr_bounds[:, 0] >= res.success_rate - 1e-12)
    assert np.all((res.mu > 0) & (res.mu <= 1))
    need = ~(1.0 - res.sr_bounds[:, 0] <= 0.01)
    assert need.any()
    mu = amb.ffrt_thresholds(grp.Qa[need], 0.01, 2000, seed=len(grp.Qa))
    assert np.array_equal(res.mu[need], mu)
    assert np.array_equal(res.accepted, res.finished & (1.0 / res.ratio <= res.mu))
    none = resolve(grp, "lambda", F, FixPolicy(validation="none"))
    assert none.accepted.all() and np.isnan(none.mu).all()
    with pytest.raises(AttitudeInputError, match="estimator.validation"):
        resolve(grp, "clambda", F, FixPolicy(validation="ffrt"))
    with pytest.raises(AttitudeInputError, match="estimator.validation"):
        resolve(grp, "lambda", F, FixPolicy(validation="strict"))


@pytest.mark.parametrize("method", ["lambda", "clambda", "mclambda"])
def test_pf_validation_accepts_only_ratio_passes_whose_ils_failure_rate_is_held(method):
    """validation=pf (the default): an epoch is accepted exactly where the method's own ratio test passes, its
    fix is the unconstrained ILS fix (searched here independently) whose ratio passes too, and the ILS failure
    rate is proven <= pf: the success-rate lower bound >= 1 - pf, or ILS best / 2nd <= the calibrated FFRT mu."""
    rng = np.random.default_rng(12)
    obs, _ = _obs(rng, attitude_from_euler(0.0, 0.0, 0.4).as_matrix(), m=30, s=7, sig_phi=0.003, sig_p=0.2)
    (grp,) = float_solution(obs)
    policy = FixPolicy(pf=0.01, ffrt_samples=2000)
    res = resolve(grp, method, F, policy)
    own = resolve(grp, method, F, FixPolicy(validation="ratio"))
    ils = amb.ils_batch(grp.a_hat, grp.Qa, n_cands=2)
    best_2nd = ils.sqnorms[:, 0] / ils.sqnorms[:, 1]
    same = np.all(ils.candidates[:, 0] == np.nan_to_num(own.z, nan=0.5), axis=1) & (best_2nd <= 1 / 3)
    held = (1.0 - res.sr_bounds[:, 0] <= 0.01) | (best_2nd <= res.mu)
    assert np.array_equal(res.accepted, own.accepted & same & held) and res.accepted.any()
    assert np.array_equal(np.isfinite(res.mu), own.accepted & same)  # calibrated only where needed
    assert method == "lambda" or (own.accepted & ~res.accepted).any()  # constrained ratio passes rejected here
    assert np.array_equal(resolve(grp, method, F, policy).accepted, res.accepted)  # deterministic
