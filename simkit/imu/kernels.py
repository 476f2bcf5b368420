"""The IMU's compiled kernel: the quantizer, whose rounding carries a remainder sample by sample (numba). Imported
by :mod:`.noise` on first use, so an IMU without quantization does not start numba."""
from __future__ import annotations

import math

import numba


@numba.njit(cache=True)
def quantize(v, step, residual, out):  # pragma: no cover - compiled
    """out[k] = v[k] + residual rounded to a multiple of ``step``, the remainder carried in ``residual`` (axes,)."""
    n, axes = v.shape
    for a in range(axes):
        r = residual[a]
        for k in range(n):
            x = r + v[k, a]
            q = math.floor(x / step + 0.5) * step
            r = x - q
            out[k, a] = q
        residual[a] = r

