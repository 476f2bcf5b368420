"""Per-epoch checks of Wang 2018's claims C1-C3, C6 and the pair statistics of C7 (the claims are
listed in docs/validation.md).

Mathematical claims (C1-C3) are checked against an independent computation with a tolerance from the matrix
condition; empirical claims (C6, C7) return which epochs / pairs hold, for fractions and counter-examples.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .gramian import gramian
from .observability import RANK_RTOL, rank

EPS = np.finfo(float).eps
ANGLE_PAIRS = ((0, 1), (0, 2), (1, 2))


def c1_error(L, sigma, atd) -> tuple[np.ndarray, np.ndarray]:
    """C1 (Theorem 1): ATDOP from the SVD vs sqrt(diag(L^+)) by numpy (LU inverse for full rank, SVD-based
    pseudo-inverse otherwise), on the angles with a finite ATDOP. Returns the worst relative error (N,) and its
    allowance (N,): 1e3 eps cond(L) on the observable subspace (rounding of both paths), at least 1e-9."""
    full = sigma[:, -1] > RANK_RTOL * sigma[:, 0]
    inv = np.empty_like(L)
    if full.any():
        inv[full] = np.linalg.inv(L[full])
    if (~full).any():
        inv[~full] = np.linalg.pinv(L[~full], rcond=RANK_RTOL, hermitian=False)
    ref = np.sqrt(np.clip(np.diagonal(inv, axis1=-2, axis2=-1), 0.0, None))
    finite = np.isfinite(atd)
    rel = np.where(finite, np.abs(atd - ref) / np.where(ref > 0, ref, 1.0), 0.0).max(axis=-1)
    kept = np.where(sigma > RANK_RTOL * sigma[:, :1], sigma, np.inf).min(axis=-1)
    allow = np.maximum(1e-9, 1e3 * EPS * sigma[:, 0] / kept)
    return rel, allow


def c2_error(L, degree) -> np.ndarray:
    """C2 (eqs 13-15): observable degree from the SVD vs the closed form sqrt((L^2)_ii) = |L[:, i]|; relative
    to sigma_max, (N,). Allowance: 1e-9."""
    ref = np.linalg.norm(L, axis=-2)
    scale = np.maximum(np.abs(L).max(axis=(-1, -2)), 1e-300)
    return np.abs(degree - ref).max(axis=-1) / scale


def c3_agree(H, rng) -> np.ndarray:
    """C3 (Theorem 2): rank(H^T R^-1 H) == rank(H^T H) for a random covariance R (symmetric positive definite,
    condition number <= 10) per row of ``H`` (N, m, 3); (N,) bool."""
    n, m = H.shape[:2]
    Q, _ = np.linalg.qr(rng.standard_normal((n, m, m)))
    lam = rng.uniform(1.0, 10.0, (n, m))
    R = np.einsum("nij,nj,nkj->nik", Q, lam, Q)
    return rank(gramian(H, R)) == rank(gramian(H))


def c6_epochs(atd, degree) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """C6 at each epoch (N, 3) arrays: over the angle pairs with different ATDOPs (inf allowed: unobservable),
    the lower ATDOP must have the strictly higher observable degree. Returns applicable (N,), held (N,) and
    the worst violation (N,): max over violated pairs of (degree of the lower-ATDOP angle's partner - its own)."""
    applicable = np.zeros(len(atd), bool)
    held = np.ones(len(atd), bool)
    worst = np.zeros(len(atd))
    for i, j in ANGLE_PAIRS:
        a_i, a_j, d_i, d_j = atd[:, i], atd[:, j], degree[:, i], degree[:, j]
        comparable = a_i != a_j
        lower_i = a_i < a_j
        d_low, d_high = np.where(lower_i, d_i, d_j), np.where(lower_i, d_j, d_i)
        bad = comparable & ~(d_low > d_high)
        applicable |= comparable
        held &= ~bad
        worst = np.maximum(worst, np.where(bad, d_high - d_low, 0.0))
    return applicable, held, worst


@njit(cache=True)
def _count_inversions(x):
    """Pairs i < j with x[i] > x[j] in ``x`` (bottom-up merge sort, O(n log n))."""
    n = x.size
    a = x.copy()
    b = np.empty_like(a)
    count = 0
    width = 1
    while width < n:
        for lo in range(0, n, 2 * width):
            mid = min(lo + width, n)
            hi = min(lo + 2 * width, n)
            i, j, k = lo, mid, lo
            while i < mid and j < hi:
                if a[i] <= a[j]:
                    b[k] = a[i]
                    i += 1
                else:
                    b[k] = a[j]
                    count += mid - i
                    j += 1
                k += 1
            b[k:k + mid - i] = a[i:mid]
            k += mid - i
            b[k:k + hi - j] = a[j:hi]
        a, b = b, a
        width *= 2
    return count


def c7_pairs(atd, degree) -> tuple[int, int, np.ndarray | None]:
    """C7 over all pairs of epochs of one angle, same satellite count: (``atd``, ``degree``) (N,) with finite
    ATDOP. A pair with different ATDOPs holds when the lower ATDOP has the strictly higher degree. Returns
    (comparable pairs, held pairs, counter-example index pair or None): the violated pair (lower ATDOP first)
    with the largest degree excess, when any."""
    order = np.lexsort((degree, atd))                       # by ATDOP, ties by ascending degree
    a, d = atd[order], degree[order]
    n = a.size
    _, ties = np.unique(a, return_counts=True)
    comparable = n * (n - 1) // 2 - int((ties * (ties - 1) // 2).sum())
    held = int(_count_inversions(d)) if n > 1 else 0
    # worst violation: each epoch against the lowest degree among epochs of strictly lower ATDOP
    pm = np.minimum.accumulate(d)
    arg = np.maximum.accumulate(np.where(d == pm, np.arange(n), 0))
    start = np.unique(a, return_index=True)[1]
    group_start = start[np.searchsorted(start, np.arange(n), side="right") - 1]
    has_lower = group_start > 0
    prev = np.maximum(group_start - 1, 0)
    excess = np.where(has_lower, d - pm[prev], -np.inf)
    example = None
    if n > 1 and excess.max() >= 0:
        j = int(np.argmax(excess))
        example = np.array([order[arg[prev[j]]], order[j]])
    return comparable, held, example
