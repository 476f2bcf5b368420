"""Symmetric 3x3 eigendecomposition for millions of Gramians: cyclic Jacobi rotations in numba.

numpy's batched ``eigh`` calls LAPACK once per 3x3 matrix (~2 us each, mostly call overhead); a Jacobi sweep
costs a few dozen flops and converges quadratically (3-5 sweeps to machine precision), and keeps small
eigenvalues of positive semi-definite matrices to high relative accuracy. Checked against numpy.linalg.eigh in
tests/test_validation_gramian.py.
"""
from __future__ import annotations

import numpy as np
from numba import njit

_PAIRS = ((0, 1), (0, 2), (1, 2))
MAX_SWEEPS = 50


@njit(cache=True)
def _rotate(a, v, p, q):
    apq = a[p, q]
    if apq == 0.0:
        return
    theta = (a[q, q] - a[p, p]) / (2.0 * apq)
    t = 1.0 / (abs(theta) + np.sqrt(theta * theta + 1.0))
    if theta < 0.0:
        t = -t
    c = 1.0 / np.sqrt(t * t + 1.0)
    s = t * c
    for k in range(3):
        akp, akq = a[k, p], a[k, q]
        a[k, p] = c * akp - s * akq
        a[k, q] = s * akp + c * akq
    for k in range(3):
        apk, aqk = a[p, k], a[q, k]
        a[p, k] = c * apk - s * aqk
        a[q, k] = s * apk + c * aqk
    a[p, q] = 0.0
    a[q, p] = 0.0
    for k in range(3):
        vkp, vkq = v[k, p], v[k, q]
        v[k, p] = c * vkp - s * vkq
        v[k, q] = s * vkp + c * vkq


@njit(cache=True)
def _eig_one(a, v):
    for _ in range(MAX_SWEEPS):
        off = a[0, 1] ** 2 + a[0, 2] ** 2 + a[1, 2] ** 2
        diag = a[0, 0] ** 2 + a[1, 1] ** 2 + a[2, 2] ** 2
        if off <= 1e-34 * (diag + 2.0 * off) or off == 0.0:
            return
        _rotate(a, v, 0, 1)
        _rotate(a, v, 0, 2)
        _rotate(a, v, 1, 2)


@njit(cache=True)
def sym_eig3(A):
    """Eigenvalues (N, 3) sorted by descending absolute value and eigenvectors (N, 3, 3) (columns) of the
    symmetric matrices ``A`` (N, 3, 3) (the upper triangle is read)."""
    n = A.shape[0]
    w = np.empty((n, 3))
    V = np.empty((n, 3, 3))
    a = np.empty((3, 3))
    v = np.empty((3, 3))
    for m in range(n):
        for i in range(3):
            for j in range(3):
                a[i, j] = A[m, min(i, j), max(i, j)]
                v[i, j] = 1.0 if i == j else 0.0
        _eig_one(a, v)
        i0, i1, i2 = _order3(abs(a[0, 0]), abs(a[1, 1]), abs(a[2, 2]))
        for j, src in ((0, i0), (1, i1), (2, i2)):
            w[m, j] = a[src, src]
            for i in range(3):
                V[m, i, j] = v[i, src]
    return w, V


@njit(cache=True)
def _order3(x0, x1, x2):
    """Indices of three values in descending order (stable)."""
    i0, i1, i2 = 0, 1, 2
    if x1 > x0:
        i0, i1 = 1, 0
        x0, x1 = x1, x0
    if x2 > x1:
        i1, i2 = 2, i1
        x1, x2 = x2, x1
        if x1 > x0:
            i0, i1 = i1, i0
    return i0, i1, i2
