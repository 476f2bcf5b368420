"""The range error an orbit error makes at each antenna: |x + d| - |x| for the antenna-to-satellite vector x and
the orbit error d (ECEF, m), at the epoch and at +-h s along the relative motion (for its rate).

The orbit error is given in the satellite's radial, along-track and cross-track axes (RAC, as
:func:`simkit.gnss.ephemeris_errors.rac_axes` defines them: R along the position, C along r x v with v the
inertial velocity, A = C x R) and turned into ECEF once per satellite, epoch and step; then one compiled pass over
epochs x antennas x satellites, with x = los range + s v_rel and norms summed x, y, z as in
``np.linalg.norm(x + d, axis=-1) - np.linalg.norm(x, axis=-1)``.
"""
from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, inline="always", error_model="numpy")
def _ecef_error(p0, p1, p2, w0, w1, w2, r, a, c):
    """Orbit error (radial ``r``, along ``a``, cross ``c``) m in ECEF for a satellite at ``p`` with inertial
    velocity ``w``."""
    n = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
    r0, r1, r2 = p0 / n, p1 / n, p2 / n
    k0, k1, k2 = p1 * w2 - p2 * w1, p2 * w0 - p0 * w2, p0 * w1 - p1 * w0
    n = math.sqrt(k0 * k0 + k1 * k1 + k2 * k2)
    k0, k1, k2 = k0 / n, k1 / n, k2 / n
    a0, a1, a2 = k1 * r2 - k2 * r1, k2 * r0 - k0 * r2, k0 * r1 - k1 * r0
    return r0 * r + a0 * a + k0 * c, r1 * r + a1 * a + k1 * c, r2 * r + a2 * a + k2 * c


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _ranges(los, rng, rel, pos, vel, v_in, rac, rac_rate, steps, out):
    d = np.empty((steps.shape[0], 3))
    for m in range(los.shape[0]):
        for c in range(los.shape[2]):
            for j in range(steps.shape[0]):
                s = steps[j]
                d[j, 0], d[j, 1], d[j, 2] = _ecef_error(
                    pos[m, c, 0] + s * vel[m, c, 0], pos[m, c, 1] + s * vel[m, c, 1], pos[m, c, 2] + s * vel[m, c, 2],
                    v_in[m, c, 0], v_in[m, c, 1], v_in[m, c, 2], rac[m, c, 0] + s * rac_rate[m, c, 0],
                    rac[m, c, 1] + s * rac_rate[m, c, 1], rac[m, c, 2] + s * rac_rate[m, c, 2])
            for a in range(los.shape[1]):
                r = rng[m, a, c]
                for j in range(steps.shape[0]):
                    s = steps[j]
                    x0 = los[m, a, c, 0] * r + s * rel[m, a, c, 0]
                    x1 = los[m, a, c, 1] * r + s * rel[m, a, c, 1]
                    x2 = los[m, a, c, 2] * r + s * rel[m, a, c, 2]
                    y0, y1, y2 = x0 + d[j, 0], x1 + d[j, 1], x2 + d[j, 2]
                    out[j, m, a, c] = math.sqrt(y0 * y0 + y1 * y1 + y2 * y2) - math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)


def range_errors(los, rng, rel, pos, vel, v_in, rac, rac_rate, steps) -> np.ndarray:
    """|x_j + d_j| - |x_j| (J, M, A, C) m at the time steps ``steps`` (J,) s: x_j = ``los`` (M, A, C, 3) x ``rng``
    (M, A, C) m + s_j ``rel`` (M, A, C, 3) m/s (satellite minus antenna velocity); d_j the orbit error ``rac`` +
    s_j ``rac_rate`` (M, C, 3) m, m/s (radial, along, cross) turned into ECEF along the RAC axes of a satellite at
    ``pos`` + s_j ``vel`` (M, C, 3) m with inertial velocity ``v_in`` (M, C, 3) m/s."""
    args = [np.ascontiguousarray(x, dtype=float) for x in (los, rng, rel, pos, vel, v_in, rac, rac_rate, steps)]
    out = np.empty((args[-1].size,) + args[1].shape)
    _ranges(*args, out)
    return out
