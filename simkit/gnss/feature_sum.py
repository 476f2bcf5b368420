"""Sums of random Fourier features, sum_f cos(k_f . x + w_f t + phase_f), at clusters of nearby points.

The truth ionosphere (:mod:`simkit.gnss.iono_truth`) evaluates its field at every antenna of a rigid body and at
+-h s around each epoch: points metres apart for a field correlated over hundreds of kilometres. The kernel takes
one sine and cosine per feature at the cluster's base point (antenna 0 at the epoch) and reaches every member by
the angle-addition formula, cos(a + d) = cos a cos d - sin a sin d, with d = k . (x - x_base) + w (t - t_base)
taken directly from the differences (more accurate than differencing two large phases) and cos d, sin d by their
Taylor series while |d| <= :data:`SMALL` (truncation below 1e-18 relative); a larger d falls back to the full phase.

The sine and cosine of the base phases use a Cody-Waite reduction by pi/2 (three parts of pi/2 whose products
with the quadrant number are exact below 2^20 quadrants) and fdlibm's minimax polynomials on [-pi/4, pi/4]
(within 2 ulp of libm), branch-free so that the feature loop vectorises; phases beyond :data:`REDUCE_MAX` rad
use libm.
"""
from __future__ import annotations

import math

import numba
import numpy as np

SMALL = 1e-3          # |d| (rad) up to which cos d and sin d come from their Taylor series
_SUM = {"reassoc"}    # sums over features may be reordered (vectorised): a last-bit difference, deterministic
REDUCE_MAX = 1e5      # |phase| (rad) up to which the three-part reduction is exact
_TWO_OVER_PI = 0.63661977236758134308
_PIO2_1 = 1.57079632673412561417e+00   # the first 33 bits of pi/2
_PIO2_2 = 6.07710050630396597660e-11   # the next 33 bits
_PIO2_3 = 2.02226624879595063154e-21   # the rest
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11


@numba.njit(cache=True, inline="always")
def _sincos(x):
    """(sin x, cos x) for |x| <= REDUCE_MAX, without branches."""
    n = math.floor(x * _TWO_OVER_PI + 0.5)
    r = ((x - n * _PIO2_1) - n * _PIO2_2) - n * _PIO2_3
    z = r * r
    s = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    c = 1.0 - 0.5 * z + z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    q = n - 4.0 * math.floor(0.25 * n)          # quadrant 0..3, kept in floating point (vectorises)
    odd = q == 1.0 or q == 3.0
    sin_x = (c if odd else s) * (-1.0 if q >= 2.0 else 1.0)
    cos_x = (s if odd else c) * (-1.0 if q == 1.0 or q == 2.0 else 1.0)
    return sin_x, cos_x


@numba.njit(cache=True, nogil=True)
def _base(k, w, phase, x, t, sin_a, cos_a, reach):
    """sin and cos of the phases k . x + w t + phase of every feature at one point ``x`` (3,) and time ``t``."""
    bound = reach[0] * math.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) + reach[1] * abs(t) + reach[2]
    if bound <= REDUCE_MAX:
        for f in range(k.shape[1]):
            sin_a[f], cos_a[f] = _sincos(k[0, f] * x[0] + k[1, f] * x[1] + k[2, f] * x[2] + w[f] * t + phase[f])
        return
    for f in range(k.shape[1]):  # huge or not finite
        a = k[0, f] * x[0] + k[1, f] * x[1] + k[2, f] * x[2] + w[f] * t + phase[f]
        sin_a[f], cos_a[f] = math.sin(a), math.cos(a)


@numba.njit(cache=True, nogil=True, fastmath=_SUM)
def _member(k, w, phase, sin_a, cos_a, x, x0, t, dt, reach):
    """sum_f cos(phase_f at ``x``, ``t`` + ``dt``) from the base point ``x0`` at ``t`` (sines and cosines);
    ``reach`` (max |k_f|, max |w_f|) bounds |d|."""
    dx0, dx1, dx2 = x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]
    total = 0.0
    if reach[0] * math.sqrt(dx0 * dx0 + dx1 * dx1 + dx2 * dx2) + reach[1] * abs(dt) <= SMALL:
        for f in range(k.shape[1]):
            d = k[0, f] * dx0 + k[1, f] * dx1 + k[2, f] * dx2 + w[f] * dt
            z = d * d
            cos_d = 1.0 - z * (0.5 - z * (1.0 / 24.0))
            sin_d = d * (1.0 - z * (1.0 / 6.0 - z * (1.0 / 120.0)))
            total += cos_a[f] * cos_d - sin_a[f] * sin_d
        return total
    for f in range(k.shape[1]):  # far from the base, or not finite
        total += math.cos(k[0, f] * x[0] + k[1, f] * x[1] + k[2, f] * x[2] + w[f] * (t + dt) + phase[f])
    return total


@numba.njit(cache=True, nogil=True, fastmath=_SUM)
def _clusters(k, w, phase, reach, x, t, dt, out):
    n_feat = k.shape[1]
    sin_a, cos_a = np.empty(n_feat), np.empty(n_feat)
    base = x.shape[2] // 2
    for m in range(x.shape[0]):
        for c in range(x.shape[3]):
            x0 = x[m, 0, base, c]
            _base(k, w, phase, x0, t[m], sin_a, cos_a, reach)
            for a in range(x.shape[1]):
                for j in range(x.shape[2]):
                    if a == 0 and j == base:
                        total = 0.0
                        for f in range(n_feat):
                            total += cos_a[f]
                        out[m, a, j, c] = total
                    else:
                        out[m, a, j, c] = _member(k, w, phase, sin_a, cos_a, x[m, a, j, c], x0, t[m], dt[j], reach)


def feature_sums(k, w, phase, x, t, dt) -> np.ndarray:
    """sum_f cos(k_f . x + w_f (t + dt_j) + phase_f) at points ``x`` (M, A, J, C, 3) m and times ``t`` (M,) s
    shifted by ``dt`` (J,) s, J odd; features ``k`` (F, 3) rad/m, ``w`` (F,) rad/s, ``phase`` (F,) rad.

    The cluster of point (m, 0, J // 2, c) is every (m, a, j, c): antennas ``a`` and time offsets ``j`` of one
    satellite ``c`` at epoch ``m``. Returns (M, A, J, C); NaN where a point or its base is not finite."""
    k = np.ascontiguousarray(np.asarray(k, dtype=float).T)
    w, phase = np.ascontiguousarray(w, dtype=float), np.ascontiguousarray(phase, dtype=float)
    reach = np.array([np.sqrt((k * k).sum(axis=0)).max(), np.abs(w).max(), np.abs(phase).max()])
    out = np.empty(x.shape[:-1])
    _clusters(k, w, phase, reach, np.ascontiguousarray(x, dtype=float), np.ascontiguousarray(t, dtype=float),
              np.ascontiguousarray(dt, dtype=float), out)
    return out
