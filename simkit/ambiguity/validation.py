"""Validation of the fixed ambiguities: ratio tests and partial ambiguity resolution.

Ratio convention here: ``ratio = sqnorm_2nd / sqnorm_best >= 1``; a fixed-threshold test accepts when
``ratio >= threshold``. LAMBDA 3.0 writes the same test as ``sqnorm_best / sqnorm_2nd <= mu`` with ``mu =
1 / threshold``; the fixed-failure-rate functions below return ``mu`` in that convention, as the literature does.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .decorrelation import as_problem, decorrelate
from .errors import AmbiguityInputError
from .search import ils, ils_batch
from .success import bootstrap_success_rate, simulated_solutions

# Fixed threshold: 3, the default of RTKLIB (option pos2-arthres = 3.0) and the commonly used empirical value
# (e.g. Landau & Euler 1992 used 2; 3 is the common conservative choice). Equivalent to mu = 1/3.
DEFAULT_RATIO_THRESHOLD = 3.0


def ratio_test(sqnorms, threshold=DEFAULT_RATIO_THRESHOLD) -> bool:
    """Accept the best candidate when sqnorm_2nd / sqnorm_best >= ``threshold`` (a zero best norm accepts)."""
    s = np.asarray(sqnorms, dtype=float)
    if s.shape[0] < 2:
        raise AmbiguityInputError("sqnorms", "needs the two best squared norms (solve with n_cands >= 2)")
    return bool(s[1] >= threshold * s[0])


def ffrt_threshold(Q, failure_rate=1e-3, n_samples=100_000, rng=None, seed=0) -> float:
    """Fixed-failure-rate ratio-test threshold ``mu`` for the model ``Q`` (cycles^2), by Monte Carlo calibration.

    Following Verhagen & Teunissen's definition of the FF-ratio test, ``mu`` is the largest value for which
    P(wrong ILS solution and sqnorm_best / sqnorm_2nd <= mu) <= ``failure_rate``, estimated from ``n_samples``
    draws a_hat ~ N(0, Q) (``rng`` or a Generator seeded with ``seed``). When the ILS failure rate itself is
    below ``failure_rate`` every solution may be accepted and ``mu = 1`` (as in LAMBDA 3.0). The result is
    model-specific (no lookup table); its resolution is limited by ``n_samples * failure_rate`` failures.
    """
    Qm = np.asarray(Q, dtype=np.float64)
    rng = np.random.default_rng(seed) if rng is None else rng
    e = rng.standard_normal((int(n_samples), Qm.shape[0])) @ np.linalg.cholesky(Qm).T
    res = ils_batch(e, Qm, n_cands=2)
    wrong = np.any(res.candidates[:, 0, :] != 0, axis=1)
    ratios = res.sqnorms[:, 0] / res.sqnorms[:, 1]
    allowed = int(math.floor(failure_rate * n_samples))
    fail_ratios = np.sort(ratios[wrong])
    if fail_ratios.size <= allowed:
        return 1.0
    return float(np.nextafter(fail_ratios[allowed], 0.0))  # just below the (allowed+1)-th failure


def ffrt(result, mu) -> bool:
    """Fixed-failure-rate ratio test: accept when sqnorm_best / sqnorm_2nd <= ``mu``."""
    return bool(result.sqnorms[0] <= mu * result.sqnorms[1])


@dataclass(frozen=True)
class PartialFix:
    """Partial ambiguity resolution (Teunissen et al. 1999; LAMBDA 3.0 ``parsearch`` semantics).

    ``n_fixed`` decorrelated ambiguities ``z_p = Z_fixed^T a`` (integer combinations of the original ones) are
    fixed to ``z_fixed`` with bootstrapped success rate ``success_rate`` >= P0; ``a_conditioned`` / ``Q_conditioned``
    are the float ambiguities and covariance given those fixes (cycles, cycles^2). n_fixed = 0: nothing fixed.
    """

    n_fixed: int
    success_rate: float | None
    Z_fixed: np.ndarray  # (n, n_fixed) int64
    z_fixed: np.ndarray  # (n_fixed,) int64, best
    sqnorms: np.ndarray  # squared norms of the subset search
    a_conditioned: np.ndarray
    Q_conditioned: np.ndarray


def partial_fix(a_hat, Q, p0=0.995, n_cands=2) -> PartialFix:
    """Fix the largest subset ``z[k:]`` of the decorrelated ambiguities whose bootstrapped success rate >= ``p0``.

    The subsets are nested from the last decorrelated ambiguity (the first one the search fixes), so the
    success rate of ``z[k:]`` is prod over i >= k of (2 Phi(1/(2 sqrt(d_i))) - 1).
    """
    a, Qm = as_problem(a_hat, Q)
    shift = np.floor(a + 0.5)
    dec = decorrelate(Qm, a - shift)
    n = a.size
    k, ps = n, None
    for start in range(n):
        p = bootstrap_success_rate(d=dec.d[start:])
        if p >= p0:
            k, ps = start, p
            break
    if k == n:
        return PartialFix(0, None, np.zeros((n, 0), np.int64), np.zeros(0, np.int64), np.zeros(0), a, Qm)
    sub = slice(k, n)
    res = ils(dec.z_hat[sub], dec.Qz[sub, sub], n_cands=n_cands)
    Zp = dec.Z[:, sub]
    zfix = res.candidates[0] + Zp.T @ shift.astype(np.int64)
    QZ = Qm @ Zp.astype(float)
    gain = np.linalg.solve(dec.Qz[sub, sub], QZ.T).T
    a_c = a - gain @ (Zp.T.astype(float) @ a - zfix)
    Q_c = Qm - gain @ QZ.T
    return PartialFix(n - k, ps, Zp, zfix, res.sqnorms, a_c, 0.5 * (Q_c + Q_c.T))


def ffrt_thresholds(Q, failure_rate=1e-3, n_samples=10_000, rng=None, seed=0, chunk=50_000):
    """:func:`ffrt_threshold` for each covariance of a stack ``Q`` (K, n, n), the draws of all problems solved in
    batches of about ``chunk``: (K,) mu (accept when sqnorm_best / sqnorm_2nd <= mu). Deterministic for a seed."""
    Qs = np.asarray(Q, dtype=np.float64)
    if Qs.ndim != 3:
        raise AmbiguityInputError("Q", f"shape {Qs.shape}; expected (K, n, n)")
    rng = np.random.default_rng(seed) if rng is None else rng
    N = int(n_samples)
    allowed = int(math.floor(failure_rate * N))
    mu = np.ones(Qs.shape[0])
    for k, res in simulated_solutions(Qs, N, rng, 2, chunk):
        wrong = np.any(res.candidates[:, 0, :] != 0, axis=1)
        ratio = np.where(wrong, res.sqnorms[:, 0] / res.sqnorms[:, 1], np.inf).reshape(-1, N)
        cut = np.sort(ratio, axis=1)[:, allowed]  # the (allowed+1)-th failure; inf: too few failures
        mu[k] = np.where(np.isfinite(cut), np.nextafter(cut, 0.0), 1.0)
    return mu
