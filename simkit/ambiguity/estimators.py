"""Integer rounding and integer bootstrapping, in the original or the decorrelated parametrisation."""
from __future__ import annotations

import numpy as np

from .decorrelation import as_problem, decorrelate, ltdl


def round_half_up(x):
    """Nearest integer, halves up (float array): the rounding every estimator here uses."""
    return np.floor(x + 0.5)


def bootstrap_z(zhat, L):
    """Sequential conditional rounding from index n-1 down to 0 (``Q = L^T diag(d) L``), as floats.

    ``zhat`` (..., n): leading axes are independent problems sharing ``L`` (the Monte Carlo success rate passes
    all its samples at once).
    """
    zhat = np.asarray(zhat, dtype=np.float64)
    n = zhat.shape[-1]
    z = np.empty_like(zhat)
    e = np.zeros_like(zhat)  # z_j - zcond_j for the levels already fixed
    for k in range(n - 1, -1, -1):
        zc = zhat[..., k] + e[..., k + 1:] @ L[k + 1:, k]
        z[..., k] = round_half_up(zc)
        e[..., k] = z[..., k] - zc
    return z


def rounding(a_hat, Q=None, decorrelate_first=True):
    """Integer rounding of ``a_hat`` (cycles) -> (n,) int64; in the decorrelated space when ``Q`` is given and
    ``decorrelate_first`` (then rounded z is mapped back with ``a = Z^-T z``)."""
    if Q is None or not decorrelate_first:
        a = np.asarray(a_hat, dtype=np.float64)
        return round_half_up(a).astype(np.int64)
    a, Qm = as_problem(a_hat, Q)
    shift = round_half_up(a)
    dec = decorrelate(Qm, a - shift)
    return dec.Zti @ round_half_up(dec.z_hat).astype(np.int64) + shift.astype(np.int64)


def bootstrapping(a_hat, Q, decorrelate_first=True):
    """Integer bootstrapping (sequential conditional rounding, from index n-1 down) -> (n,) int64."""
    a, Qm = as_problem(a_hat, Q)
    shift = round_half_up(a)
    if decorrelate_first:
        dec = decorrelate(Qm, a - shift)
        return dec.Zti @ bootstrap_z(dec.z_hat, dec.L).astype(np.int64) + shift.astype(np.int64)
    L, _ = ltdl(Qm)
    return bootstrap_z(a - shift, L).astype(np.int64) + shift.astype(np.int64)
