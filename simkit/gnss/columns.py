"""Output arrays (M, A, S) from the values of some satellite columns (M, A, C): one compiled pass that writes
every element once (the fill elsewhere, NaN where a signal is not tracked), instead of a full array of the fill, a
masked copy of the values and a fancy-indexed assignment."""
from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def _place(x, cols, keep, masked, fill, out):
    for m in range(out.shape[0]):
        for a in range(out.shape[1]):
            row = out[m, a]
            row[:] = fill
            for c in range(cols.shape[0]):
                row[cols[c]] = x[m, a, c] if not masked or keep[m, a, c] else np.nan


_ALL = np.ones((1, 1, 1), np.bool_)


def place_columns(x, cols, n_cols: int, keep=None, fill: float = np.nan) -> np.ndarray:
    """(M, A, ``n_cols``) float64 array holding ``x`` (M, A, C) in the columns ``cols`` (C,) int, NaN where ``keep``
    (M, A, C) bool (optional) is False, and ``fill`` in the other columns."""
    x = np.asarray(x, dtype=float)
    if x.ndim != 3 or x.shape[2] != len(cols) or (keep is not None and x.shape != keep.shape):
        shape = np.broadcast_shapes(x.shape, (1, 1, len(cols)) if keep is None else np.shape(keep))
        x = np.broadcast_to(x, shape)
    if not x.flags.c_contiguous:
        x = np.ascontiguousarray(x)
    if cols.dtype != np.int64 or not cols.flags.c_contiguous:
        cols = np.ascontiguousarray(cols, dtype=np.int64)
    out = np.empty(x.shape[:2] + (n_cols,))
    if keep is None:
        _place(x, cols, _ALL, False, float(fill), out)
    else:
        _place(x, cols, np.ascontiguousarray(keep, dtype=np.bool_), True, float(fill), out)
    return out


def consecutive(idx: np.ndarray):
    """The indices ``idx`` (K,) as a slice when they are consecutive and increasing (indexing with it gives views,
    not copies), else ``idx`` itself."""
    if idx.size and np.all(np.diff(idx) == 1):
        return slice(int(idx[0]), int(idx[-1]) + 1)
    return idx
