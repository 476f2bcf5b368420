"""simkit.ambiguity against RTKLIB's C lambda (pyrtklib) and brute-force enumeration on random problems,
Monte Carlo checks of the success rates, the work cap and the input errors."""
import numpy as np
import pytest

from simkit import ambiguity as amb
from studies.ambiguity_problems import random_problem

N_PROBLEMS = 10_000


def _sizes(rng):
    """n = 2..40: mostly small/medium, a share up to 40; half well, half badly conditioned."""
    n = np.concatenate([rng.integers(2, 11, 6000), rng.integers(11, 21, 3000), rng.integers(21, 41, 1000)])
    return n, np.where(rng.random(n.size) < 0.5, "well", "bad")


class _Rtklib:
    """RTKLIB's lambda with buffers allocated once per size."""

    def __init__(self):
        import pyrtklib

        self.mod = pyrtklib
        self.fn = getattr(self.mod, "lambda")
        self.buf = {}

    def __call__(self, a, Q, m=2):
        n = a.size
        if n not in self.buf:
            A = self.mod.Arr1Ddouble
            self.buf[n] = (A(n), A(n * n), A(n * m), A(m))
        ab, Qb, F, s = self.buf[n]
        for i, v in enumerate(a.tolist()):
            ab[i] = v
        for i, v in enumerate(Q.T.ravel().tolist()):
            Qb[i] = v
        if self.fn(n, m, ab, Qb, F, s) != 0:
            return None
        cands = np.rint(np.array([F[i] for i in range(n * m)]).reshape(m, n)).astype(np.int64)
        return cands, np.array([s[i] for i in range(m)])


def _same_pair(ours, theirs, s_ours):
    """Best and second best equal; when the two norms tie (within rounding), their order may differ."""
    if np.array_equal(ours, theirs):
        return True
    if abs(s_ours[1] - s_ours[0]) <= 1e-9 * s_ours[1]:
        return sorted(map(tuple, ours.tolist())) == sorted(map(tuple, theirs.tolist()))
    return False


def test_ils_equals_rtklib_on_10000_random_problems():
    rtk = _Rtklib()
    rng = np.random.default_rng(20240606)
    sizes, conds = _sizes(rng)
    compared = skipped = 0
    for n, cond in zip(sizes, conds):
        a, Q, _ = random_problem(rng, int(n), cond)
        ours = amb.ils(a, Q, n_cands=2)
        assert ours.status == "finished"
        theirs = rtk(a, Q)
        if theirs is None:  # RTKLIB gave up after 10,000 loops
            skipped += 1
            continue
        assert _same_pair(ours.candidates, theirs[0], ours.sqnorms), (n, cond)
        np.testing.assert_allclose(ours.sqnorms, theirs[1], rtol=1e-6)
        compared += 1
    print(f"compared {compared} problems with RTKLIB, {skipped} where RTKLIB did not finish")
    assert compared >= 9_000


def test_ils_equals_brute_force_for_small_n():
    rng = np.random.default_rng(7)
    done = 0
    for k in range(600):
        n = 2 + k % 5  # 2..6
        a, Q, _ = random_problem(rng, n, "bad" if k % 2 else "well")
        ours = amb.ils(a, Q, n_cands=3)
        cands, sq = amb.enumerate_ils(a, Q, n_cands=3)
        np.testing.assert_allclose(ours.sqnorms, sq, rtol=1e-9)
        for i in range(3):  # equal up to exact ties
            if not np.array_equal(ours.candidates[i], cands[i]):
                assert np.isclose(sq[i], sq[i - 1] if i else sq[1], rtol=1e-12)
        done += 1
    assert done == 600


def test_batch_equals_single_and_list_api():
    rng = np.random.default_rng(3)
    probs = [random_problem(rng, 8, "bad") for _ in range(50)]
    A = np.stack([p[0] for p in probs])
    Qs = np.stack([p[1] for p in probs])
    batch = amb.ils_batch(A, Qs, n_cands=2)
    for k, (a, Q, _) in enumerate(probs):
        one = amb.ils(a, Q, n_cands=2)
        np.testing.assert_array_equal(batch.candidates[k], one.candidates)
        np.testing.assert_array_equal(batch.sqnorms[k], one.sqnorms)
    mixed = [random_problem(rng, n, "well") for n in (3, 5, 3, 7)]
    out = amb.ils_batch([m[0] for m in mixed], [m[1] for m in mixed])
    for (a, Q, _), (cands, sq, finished) in zip(mixed, out):
        assert finished
        np.testing.assert_array_equal(cands, amb.ils(a, Q).candidates)


def test_integer_shift_keeps_precision_for_huge_floats():
    rng = np.random.default_rng(11)
    a, Q, _ = random_problem(rng, 10, "well", magnitude=1e3)
    base = amb.ils(a, Q, n_cands=2)
    offset = rng.integers(-10**7, 10**7, 10)
    big = amb.ils(a + offset, Q, n_cands=2)
    np.testing.assert_array_equal(big.candidates, base.candidates + offset)
    np.testing.assert_allclose(big.sqnorms, base.sqnorms, rtol=1e-8)


@pytest.mark.parametrize("cond,n", [("well", 6), ("bad", 5), ("bad", 10)])
def test_bootstrap_success_rate_matches_monte_carlo(cond, n):
    rng = np.random.default_rng(100 + n)
    _, Q, _ = random_problem(rng, n, cond)
    while amb.bootstrap_success_rate(Q) > 0.9:  # an informative success rate
        Q = 2.0 * Q
    exact = amb.bootstrap_success_rate(Q)
    n_mc = 40_000
    p, _ = amb.monte_carlo_success_rate(Q, n_mc, np.random.default_rng(5), estimator="bootstrap")
    sigma = np.sqrt(exact * (1 - exact) / n_mc)
    assert abs(p - exact) <= 3 * sigma, (p, exact, sigma)
    p_ils, s_ils = amb.monte_carlo_success_rate(Q, 20_000, np.random.default_rng(6), estimator="ils")
    assert p_ils >= exact - 3 * s_ils  # IB is a lower bound of ILS
    assert p_ils <= amb.adop_upper_bound(Q) + 3 * s_ils


def test_ffrt_threshold_controls_the_failure_rate():
    rng = np.random.default_rng(21)
    _, Q, _ = random_problem(rng, 6, "bad")
    while amb.bootstrap_success_rate(Q) > 0.8:  # an ILS failure rate well above the tolerance
        Q = 2.0 * Q
    pf = 0.01
    mu = amb.ffrt_threshold(Q, failure_rate=pf, n_samples=40_000, seed=2)
    e = np.random.default_rng(9).standard_normal((40_000, 6)) @ np.linalg.cholesky(Q).T
    res = amb.ils_batch(e, Q)
    accepted = res.sqnorms[:, 0] <= mu * res.sqnorms[:, 1]
    failed = np.any(res.candidates[:, 0] != 0, axis=1)
    rate = np.mean(accepted & failed)
    assert rate <= pf + 3 * np.sqrt(pf / 40_000)
    assert 0.0 < mu < 1.0


def test_work_cap_reports_not_finished():
    rng = np.random.default_rng(5)
    a, Q, _ = random_problem(rng, 30, "bad")
    capped = amb.ils(a, Q, n_cands=2, max_nodes=20)
    assert capped.status == "not finished" and not capped.finished
    full = amb.ils(a, Q, n_cands=2)
    assert full.status == "finished" and full.nodes > 20
    batch = amb.ils_batch(a[None], Q[None], max_nodes=20)
    assert list(batch.status) == ["not finished"]


def test_ratio_test_fixed_threshold():
    assert amb.ratio_test([1.0, 3.5])
    assert not amb.ratio_test([1.0, 2.9])
    assert amb.ratio_test([1.0, 2.1], threshold=2.0)


@pytest.mark.parametrize("a,Q,what,words", [
    (np.zeros(3), np.eye(2), "Q", "shape"),
    (np.zeros((3, 1)), np.eye(3), "a_hat", "shape"),
    (np.array([0.0, np.nan]), np.eye(2), "a_hat", "NaN"),
    (np.zeros(2), np.array([[1.0, 0.5], [0.4, 1.0]]), "Q", "not symmetric"),
    (np.zeros(2), np.array([[1.0, 2.0], [2.0, 1.0]]), "Q", "not positive definite"),
    (np.zeros(2), np.array([[1.0, 0.0], [0.0, np.inf]]), "Q", "not finite"),
])
def test_bad_input_raises_one_clear_error(a, Q, what, words):
    with pytest.raises(amb.AmbiguityInputError) as err:
        amb.ils(a, Q)
    assert err.value.what == what and words in str(err.value)
    assert isinstance(err.value, ValueError)


def test_batch_error_names_the_epoch():
    Qs = np.stack([np.eye(2), np.array([[1.0, 2.0], [2.0, 1.0]])])
    with pytest.raises(amb.AmbiguityInputError, match=r"Q\[1\].*not positive definite"):
        amb.ils_batch(np.zeros((2, 2)), Qs)
