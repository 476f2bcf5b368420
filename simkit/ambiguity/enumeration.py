"""Brute-force ILS by enumeration, a cross-check for the search on small problems (n <= ~6).

Every integer vector of a box that contains the whole candidate ellipsoid is scored with
``(a_hat - a)^T Q^-1 (a_hat - a)`` evaluated directly (Cholesky solve of the original Q), without the LtDL
recursion the search uses. The box is taken in the decorrelated space (``a = Z^-T z`` is a bijection of the
integers because Z is unimodular), where it is small; its radius comes from the ``n_cands``-th best of the
3^n neighbours of the rounded z, so it always contains the ``n_cands`` best vectors.
"""
from __future__ import annotations

import itertools

import numpy as np
from scipy.linalg import cho_factor, cho_solve

from .decorrelation import as_problem, decorrelate
from .errors import AmbiguityInputError


def _sqnorms(a, Q_cho, cands):
    v = a[None, :] - cands
    return np.einsum("ij,ij->i", v, cho_solve(Q_cho, v.T).T)


def enumerate_ils(a_hat, Q, n_cands=2, max_points=5_000_000):
    """The ``n_cands`` best integer vectors and their squared norms, by exhaustive enumeration.

    Returns (candidates (n_cands, n) int64, sqnorms (n_cands,)). Raises :class:`AmbiguityInputError` when the
    enclosing box holds more than ``max_points`` vectors.
    """
    a, Qm = as_problem(a_hat, Q)
    shift = np.floor(a + 0.5)
    a0 = a - shift
    dec = decorrelate(Qm, a0)
    cho = cho_factor(Qm)
    n = a.size
    zr = np.floor(dec.z_hat + 0.5)
    near = zr + np.array(list(itertools.product((-1, 0, 1), repeat=n)), dtype=np.float64)
    chi2 = np.sort(_sqnorms(a0, cho, near @ dec.Zti.T.astype(np.float64)))[n_cands - 1]
    half = np.sqrt(chi2 * np.diag(dec.Qz))  # the ellipsoid's extent along each z axis
    lo = np.ceil(dec.z_hat - half)
    hi = np.floor(dec.z_hat + half)
    counts = (hi - lo + 1).astype(np.int64)
    if np.prod(counts.astype(float)) > max_points:
        raise AmbiguityInputError("Q", f"enumeration box of {np.prod(counts.astype(float)):.3g} points exceeds "
                                       f"max_points={max_points}")
    grids = np.meshgrid(*[np.arange(l, h + 1) for l, h in zip(lo, hi)], indexing="ij")
    zs = np.stack([g.ravel() for g in grids], axis=1)
    cands = zs @ dec.Zti.T.astype(np.float64)
    s = _sqnorms(a0, cho, cands)
    order = np.argsort(s, kind="stable")[:n_cands]
    return (cands[order] + shift).astype(np.int64), s[order]
