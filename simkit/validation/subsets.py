"""Satellite subsets of every size at every epoch, and their line-of-sight scatters in one cumulative pass.

An ordering puts the visible satellites of each epoch first (highest elevation first, or a random permutation);
the subset of size k is the first k of the ordering, its reference satellite the first. Cumulative sums of
d d^T and d (d = e - e_ref, which keeps close lines of sight free of cancellation) along the ordering give the scatter G of every k at once (see
:func:`simkit.validation.gramian.los_scatter`), O(M S) instead of O(M S^2).
"""
from __future__ import annotations

import numpy as np

KINDS = ("highest", "random")


def ordering(elevation, visible, kind: str = "highest", rng=None) -> np.ndarray:
    """Satellite indices (M, S): visible satellites first, by descending elevation (``"highest"``) or in a random
    order drawn from ``rng`` (``"random"``); invisible satellites after them."""
    if kind == "highest":
        key = np.where(visible, -np.nan_to_num(elevation, nan=0.0), np.inf)
    else:
        key = np.where(visible, rng.random(visible.shape), np.inf)
    return np.argsort(key, axis=1, kind="stable")


def cumulative_scatter(los_b, order, k_max: int, weighting: str = "dd") -> np.ndarray:
    """Scatters G (M, k_max - 1, 3, 3) of the subsets of sizes 2..k_max: the first k satellites of ``order``
    (M, S) of the lines of sight ``los_b`` (M, S, 3). Rows beyond an epoch's visible count are meaningless (the
    caller masks them)."""
    e = np.nan_to_num(np.take_along_axis(los_b, order[:, :k_max, None], axis=1))
    d = e - e[:, :1, :]                      # about the reference: no cancellation for close lines of sight
    s2 = np.cumsum(d[..., :, None] * d[..., None, :], axis=1)       # (M, K, 3, 3)
    if weighting == "dd":
        s1 = np.cumsum(d, axis=1)
        k = np.arange(1, k_max + 1, dtype=float)[None, :, None, None]
        s2 = s2 - s1[..., :, None] * s1[..., None, :] / k
    return s2[:, 1:]
