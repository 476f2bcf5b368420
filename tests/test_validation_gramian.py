"""The Gramian against Wang 2018's closed forms (eqs 18, 19, 23 corrected), Theorem 2, the rank claims on
synthetic geometry with constructed degenerate cases, and the solvers against numpy (LAPACK) and brute force."""
import itertools

import numpy as np
import pytest

from simkit.validation import (accumulated_gramian, atdop, design_matrix, gramian, gramian_from_scatter,
                               los_scatter, observable_degree, rank, svd)
from simkit.validation.checks import c7_pairs
from simkit.validation.degeneracy import classify, expected_rank
from simkit.validation.subsets import cumulative_scatter

L1, L2 = 3.965, 9.445
B1, B2 = np.array([0.0, L1, 0.0]), np.array([L2, 0.0, 0.0])


def _sky(rng, n):
    """n unit lines of sight above 10 deg elevation (body = ENU here)."""
    az = rng.uniform(0, 2 * np.pi, n)
    el = rng.uniform(np.radians(10), np.radians(89), n)
    return np.stack([np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)], -1)


def test_eq19_and_eq18_closed_forms_for_one_double_difference():
    s = np.array([0.3, -0.2, 0.5])
    sx, sy, sz = s
    eq19 = L1**2 * np.array([[sz * sz, 0, -sz * sx], [0, 0, 0], [-sz * sx, 0, sx * sx]])
    eq18 = np.array([[L1**2 * sz * sz, 0, -L1**2 * sz * sx], [0, L2**2 * sz * sz, -L2**2 * sz * sy],
                     [-L1**2 * sz * sx, -L2**2 * sz * sy, L1**2 * sx * sx + L2**2 * sy * sy]])
    assert np.allclose(gramian(design_matrix(s[None], [B1])), eq19, rtol=1e-14, atol=1e-14)
    assert np.allclose(gramian(design_matrix(s[None], [B1, B2])), eq18, rtol=1e-14, atol=1e-14)


def test_eq23_as_corrected_in_the_errata():
    """Eq. (23)'s (3,3) element is l1^2 sum s_bx^2 (from eq. 19), not the printed l1^2 sum s_bz^2."""
    S = np.array([[0.3, -0.2, 0.5], [-0.4, 0.1, 0.2], [0.1, 0.6, -0.3]])
    L = gramian(design_matrix(S, [B1]))
    assert L[2, 2] == pytest.approx(L1**2 * (S[:, 0] ** 2).sum(), rel=1e-14)
    assert L[2, 2] != pytest.approx(L1**2 * (S[:, 2] ** 2).sum(), rel=1e-3)
    assert L[0, 2] == pytest.approx(-L1**2 * (S[:, 2] * S[:, 0]).sum(), rel=1e-14)
    assert np.all(L[1] == 0) and np.all(L[:, 1] == 0)


def test_dd_weighting_reduces_to_the_centred_scatter():
    """H^T R^-1 H with R = (I_B + J_B) (x) D D^T (equal-weight phases, shared master) equals the scatter form,
    whichever satellite is the reference."""
    rng = np.random.default_rng(3)
    e = _sky(rng, 6)
    D = np.hstack([-np.ones((5, 1)), np.eye(5)])
    R = np.kron(np.eye(2) + 1.0, D @ D.T)
    for ref in (0, 3):
        perm = [ref] + [i for i in range(6) if i != ref]
        s_dd = e[perm][1:] - e[perm][0]
        L_direct = gramian(design_matrix(s_dd, [B1, B2]), R)
        assert np.allclose(gramian_from_scatter(los_scatter(e), [B1, B2]), L_direct, rtol=1e-12)
    L_id = gramian(design_matrix(e[1:] - e[0], [B1, B2]))
    assert np.allclose(gramian_from_scatter(los_scatter(e, "identity"), [B1, B2], "identity"), L_id, rtol=1e-12)


def test_cumulative_scatter_equals_the_scatter_of_each_prefix():
    rng = np.random.default_rng(4)
    e = _sky(rng, 7)[None]
    order = np.arange(7)[None]
    for w in ("dd", "identity"):
        G = cumulative_scatter(e, order, 7, w)
        for k in range(2, 8):
            assert np.allclose(G[0, k - 2], los_scatter(e[0, :k], w), atol=1e-14)


def test_accumulated_gramian_with_transition_matrices():
    rng = np.random.default_rng(5)
    H = rng.standard_normal((4, 5, 3))
    R = np.stack([np.diag(rng.uniform(1, 2, 5)) for _ in range(4)])
    phi = rng.standard_normal((4, 3, 3))
    got = accumulated_gramian(H, R, phi)
    want = sum(phi[i].T @ H[i].T @ np.linalg.inv(R[i]) @ H[i] @ phi[i] for i in range(3))
    assert np.allclose(got[2], want, rtol=1e-12)


@pytest.mark.parametrize("k", range(2, 11))
def test_rank_claims_c4_c5_on_random_skies(k):
    """Every non-degenerate random geometry has the claimed rank; random baselines occasionally make a
    near-degenerate one (within 1e-3 rad), which must stay rare."""
    rng = np.random.default_rng(10 + k)
    degenerate = 0
    for _ in range(50):
        e = _sky(rng, k)
        for baselines, exp in (([B1], 1 if k == 2 else 2), ([B1, B2], 2 if k == 2 else 3),
                               ([rng.standard_normal(3), rng.standard_normal(3)], 2 if k == 2 else 3)):
            G = los_scatter(e)
            margin, code = classify(G[None], k, baselines)
            assert expected_rank(len(baselines), k) == exp
            if code[0]:
                degenerate += 1
                assert margin[0] < 1e-3
                continue
            assert rank(gramian_from_scatter(G, baselines)) == exp
            assert rank(gramian(design_matrix(e[1:] - e[0], baselines))) == exp
    assert degenerate <= 2


def test_degenerate_geometries_are_detected_and_lose_rank():
    up = np.array([0.0, 0.0, 1.0])
    along = np.array([0.0, np.cos(0.5), np.sin(0.5)])      # DD (along - up) lies in the y-z plane
    # dual, 2 satellites, DD parallel to the baseline
    e = np.array([[0.0, -0.6, 0.8], [0.0, 0.6, 0.8]])
    assert classify(los_scatter(e)[None], 2, [B1])[1][0] == 2
    assert rank(gramian(design_matrix(e[1:] - e[0], [B1]))) == 0
    # dual, 3 satellites, all lines of sight in the plane containing the baseline (y-z)
    e = np.array([up, along, [0.0, -np.cos(0.3), np.sin(0.3)]])
    assert classify(los_scatter(e)[None], 3, [B1])[1][0] == 3
    assert rank(gramian_from_scatter(los_scatter(e), [B1])) == 1
    # three antennas, 2 satellites, DD in the baseline (x-y) plane
    e = np.array([[0.6, 0.0, 0.8], [-0.6, 0.0, 0.8]])
    assert classify(los_scatter(e)[None], 2, [B1, B2])[1][0] == 4
    assert rank(gramian_from_scatter(los_scatter(e), [B1, B2])) == 1
    # three antennas, collinear baselines
    assert classify(los_scatter(_sky(np.random.default_rng(0), 5))[None], 5, [B1, 2 * B1])[1][0] == 7


def test_theorem2_holds_for_covariances_but_not_for_every_nonsingular_r():
    rng = np.random.default_rng(6)
    for k in range(2, 9):
        H = design_matrix(_sky(rng, k)[1:] - _sky(rng, 1)[0], [B1, B2])
        A = rng.standard_normal((len(H), len(H)))
        R = A @ A.T + 0.1 * np.eye(len(H))
        assert rank(gramian(H, R)) == rank(gramian(H))
    # a nonsingular, symmetric but indefinite R: H^T R^-1 H = 0 while H^T H has rank 1
    H = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    R = np.diag([1.0, -1.0])
    assert rank(gramian(H, R)) == 0 and rank(gramian(H)) == 1


def test_svd_against_lapack():
    rng = np.random.default_rng(7)
    A = rng.standard_normal((2000, 3, 3))
    L = A @ np.swapaxes(A, 1, 2)
    L[:500, 1, :] = L[:500, :, 1] = 0.0
    sigma, U = svd(L)
    assert np.allclose(sigma, np.linalg.svd(L, compute_uv=False), rtol=1e-12, atol=1e-13 * sigma[:, :1])
    assert np.allclose(U @ (sigma[..., None] * np.swapaxes(U, 1, 2)), L, atol=1e-12)


def test_unobservable_angle_has_infinite_atdop_and_zero_degree():
    L = gramian(design_matrix(_sky(np.random.default_rng(8), 6)[1:] - [0, 0, 1], [B1]))
    dop, deg = atdop(L), observable_degree(L)
    assert np.isinf(dop[1]) and deg[1] == 0.0
    assert np.all(np.isfinite(dop[[0, 2]]))
    full = gramian(design_matrix(_sky(np.random.default_rng(9), 6)[1:] - [0, 0, 1], [B1, B2]))
    assert np.allclose(atdop(full), np.sqrt(np.diag(np.linalg.inv(full))), rtol=1e-12)
    assert np.allclose(observable_degree(full), np.sqrt(np.diag(full @ full)), rtol=1e-12)


def test_c7_pair_count_against_brute_force():
    rng = np.random.default_rng(11)
    a = rng.integers(0, 30, 300).astype(float)
    d = rng.integers(0, 30, 300).astype(float)
    comp = held = 0
    for i, j in itertools.combinations(range(300), 2):
        if a[i] != a[j]:
            comp += 1
            lo, hi = (i, j) if a[i] < a[j] else (j, i)
            held += d[lo] > d[hi]
    got = c7_pairs(a, d)
    assert got[:2] == (comp, held)
    i, j = got[2]
    assert a[i] < a[j] and d[i] <= d[j]
