"""Output arrays (M, A, S) from the values of some satellite columns (M, A, C): one compiled pass that writes
every element once (the fill elsewhere, NaN where a signal is not tracked), instead of a full array of the fill, a
masked copy of the values and a fancy-indexed assignment."""
from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def _place(x, cols, keep, masked, fill, out):
    for m in range(out.shape[0]):
        for a in range(out.shape[1]):
            row = out[m, a]
            row[:] = fill
            for c in range(cols.shape[0]):
                row[cols[c]] = x[m, a, c] if not masked or keep[m, a, c] else np.nan


def place_columns(x, cols, n_cols: int, keep=None, fill: float = np.nan) -> np.ndarray:
    """(M, A, ``n_cols``) float64 array holding ``x`` (M, A, C) in the columns ``cols`` (C,) int, NaN where ``keep``
    (M, A, C) bool (optional) is False, and ``fill`` in the other columns."""
    cols = np.ascontiguousarray(cols, dtype=np.int64)
    shape = np.broadcast_shapes(np.shape(x), (1, 1, cols.size) if keep is None else np.shape(keep))[:2]
    x = np.ascontiguousarray(np.broadcast_to(x, shape + (cols.size,)), dtype=float)
    out = np.empty(shape + (n_cols,))
    masked = keep is not None
    keep = np.ascontiguousarray(keep, dtype=np.bool_) if masked else np.ones((1, 1, 1), np.bool_)
    _place(x, cols, keep, masked, float(fill), out)
    return out
