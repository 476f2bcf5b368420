"""The range error an orbit error makes at each antenna: |x + d| - |x| for the antenna-to-satellite vector x and
the orbit error d (ECEF, m), at the epoch and at +-h s along the relative motion (for its rate).

One compiled pass per block over epochs x antennas x satellites, with the arithmetic of the array expression it
replaces (x = los range + s v_rel; norms summed in the same order), so the values are bit for bit those of
``np.linalg.norm(x + d, axis=-1) - np.linalg.norm(x, axis=-1)``.
"""
from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def _ranges(los, rng, rel, d, steps, out):
    for m in range(los.shape[0]):
        for a in range(los.shape[1]):
            for c in range(los.shape[2]):
                r = rng[m, a, c]
                for j in range(steps.shape[0]):
                    s = steps[j]
                    x0 = los[m, a, c, 0] * r + s * rel[m, a, c, 0]
                    x1 = los[m, a, c, 1] * r + s * rel[m, a, c, 1]
                    x2 = los[m, a, c, 2] * r + s * rel[m, a, c, 2]
                    y0, y1, y2 = x0 + d[j, m, c, 0], x1 + d[j, m, c, 1], x2 + d[j, m, c, 2]
                    out[j, m, a, c] = math.sqrt(y0 * y0 + y1 * y1 + y2 * y2) - math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)


def range_errors(los, rng, rel, d, steps) -> np.ndarray:
    """|x_j + d_j| - |x_j| (J, M, A, C) m with x_j = ``los`` (M, A, C, 3) x ``rng`` (M, A, C) m + ``steps`` (J,) s x
    ``rel`` (M, A, C, 3) m/s (satellite minus antenna velocity), and ``d`` (J, M, C, 3) m the orbit error at each
    step (ECEF)."""
    los, rng, rel, d, steps = (np.ascontiguousarray(x, dtype=float) for x in (los, rng, rel, d, steps))
    out = np.empty((steps.size,) + rng.shape)
    _ranges(los, rng, rel, d, steps, out)
    return out
