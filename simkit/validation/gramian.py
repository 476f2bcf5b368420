"""The attitude-error observability Gramian of double-differenced carrier phase (Wang 2018, eqs 3, 7, 16, 17).

A DD carrier phase on baseline b (body frame, m) between satellites i and r reads s^T C b with s = e_i - e_r
the DD line of sight (difference of unit vectors antenna -> satellite). A small attitude error phi (rad, about
body x, y, z = pitch, roll, yaw) changes it by s_b^T [b x] phi (to sign, which L does not see), so for
baselines b_1..b_B the design matrix is H = [S_b^T [b_1 x]; ...; S_b^T [b_B x]] (eq. 16; B = 1 is eq. 17) and
the instantaneous Gramian is L = H^T R^-1 H (eq. 7). Baselines are arbitrary body-frame vectors.

Two noise models for R (undifferenced phase variance 1 m^2, so L is per unit variance):

- ``"dd"``: equally weighted undifferenced phases, correlated through the differencing. With all baselines
  sharing the master antenna, R = (I_B + J_B) (x) D D^T (D the n-1 x n differencing operator, J all ones). Then
  S R^-1 S^T collapses to E^T (I - 11^T / n) E: the scatter of the unit lines of sight about their mean, whatever
  the reference satellite, and L = sum_kl W_kl [b_k x]^T G [b_l x] with W = (I_B + J_B)^-1.
- ``"identity"``: R = I (the paper's "simplified equally weighted model" read literally), reference satellite
  first in the subset: G = sum_i (e_i - e_r)(e_i - e_r)^T, W = I_B.

Both give the same rank (Theorem 2); the ATDOP values differ by the weighting.
"""
from __future__ import annotations

import numpy as np

from ..frames import skew
from .errors import ValidationInputError

WEIGHTINGS = ("dd", "identity")


def _check_baselines(baselines_b) -> np.ndarray:
    b = np.atleast_2d(np.asarray(baselines_b, dtype=float))
    if b.ndim != 2 or b.shape[1] != 3 or b.shape[0] < 1 or not np.isfinite(b).all():
        raise ValidationInputError(f"baselines_b: expected finite (B, 3) body-frame vectors in m, got shape "
                                   f"{np.shape(baselines_b)}")
    return b


def design_matrix(s_dd_b, baselines_b) -> np.ndarray:
    """H of eq. (16) (eq. 17 for one baseline): ``s_dd_b`` (..., n, 3) DD lines of sight in the body frame (one
    row per double difference), ``baselines_b`` (B, 3) m; returns (..., B n, 3), baseline-major rows, m/rad."""
    s = np.asarray(s_dd_b, dtype=float)
    if s.ndim < 2 or s.shape[-1] != 3:
        raise ValidationInputError(f"s_dd_b: expected (..., n, 3) DD lines of sight, got shape {s.shape}")
    K = skew(_check_baselines(baselines_b))                       # (B, 3, 3)
    H = np.einsum("...nj,bjk->...bnk", s, K)
    return H.reshape(*s.shape[:-2], -1, 3)


def gramian(H, R=None) -> np.ndarray:
    """L = H^T R^-1 H (eq. 7) for ``H`` (..., m, 3) and ``R`` (..., m, m) nonsingular (identity when None)."""
    H = np.asarray(H, dtype=float)
    if H.ndim < 2 or H.shape[-1] != 3:
        raise ValidationInputError(f"H: expected (..., m, 3), got shape {H.shape}")
    Ht = np.swapaxes(H, -1, -2)
    if R is None:
        return Ht @ H
    R = np.asarray(R, dtype=float)
    if R.shape[-2:] != (H.shape[-2],) * 2:
        raise ValidationInputError(f"R: expected (..., {H.shape[-2]}, {H.shape[-2]}) to match H, got {R.shape}")
    return Ht @ np.linalg.solve(R, H)


def accumulated_gramian(H, R=None, phi=None) -> np.ndarray:
    """L_{k,0} = sum_{i<=k} Phi_{i,0}^T H_i^T R_i^-1 H_i Phi_{i,0} (eq. 3) for every k: ``H`` (K, m, 3), ``R``
    (K, m, m) or None, ``phi`` (K, 3, 3) transition matrices from step 0 (identity when None); (K, 3, 3)."""
    Lk = gramian(H, R)
    if phi is not None:
        phi = np.asarray(phi, dtype=float)
        if phi.shape != Lk.shape:
            raise ValidationInputError(f"phi: expected {Lk.shape} transition matrices, got {phi.shape}")
        Lk = np.swapaxes(phi, -1, -2) @ Lk @ phi
    return np.cumsum(Lk, axis=0)


def baseline_weights(n_baselines: int, weighting: str = "dd") -> np.ndarray:
    """W (B, B): the inverse of the baselines' SD covariance factor, (I + J)^-1 for ``"dd"`` (baselines sharing
    the master antenna), I for ``"identity"``."""
    if weighting not in WEIGHTINGS:
        raise ValidationInputError(f"weighting: expected one of {', '.join(WEIGHTINGS)}, got {weighting!r}")
    eye = np.eye(n_baselines)
    return np.linalg.inv(eye + 1.0) if weighting == "dd" else eye


def gramian_operator(baselines_b, weighting: str = "dd") -> np.ndarray:
    """The (9, 9) linear map vec(G) -> vec(L) with L = sum_kl W_kl [b_k x]^T G [b_l x] (row-major vec)."""
    b = _check_baselines(baselines_b)
    K = skew(b)
    W = baseline_weights(len(b), weighting)
    T = np.einsum("kl,kji,lmn->jmin", W, K, K)                    # [b_k x]^T_{ij} = K_k[j, i]
    return T.reshape(9, 9)


def gramian_from_scatter(G, baselines_b, weighting: str = "dd") -> np.ndarray:
    """L (..., 3, 3) from the line-of-sight scatter ``G`` (..., 3, 3) (see :func:`los_scatter`)."""
    G = np.asarray(G, dtype=float)
    T = gramian_operator(baselines_b, weighting)
    # (9, 9) @ (9, N) with the long axis last: 4x faster in OpenBLAS than (N, 9) @ (9, 9)
    L = (T.T @ G.reshape(-1, 9).T).T
    return np.ascontiguousarray(L).reshape(G.shape)


def los_scatter(e_b, weighting: str = "dd") -> np.ndarray:
    """G (..., 3, 3) of unit lines of sight ``e_b`` (..., n, 3) (body frame, first row the reference
    satellite): E^T (I - 11^T/n) E for ``"dd"``, sum_i (e_i - e_0)(e_i - e_0)^T for ``"identity"``."""
    e = np.asarray(e_b, dtype=float)
    if weighting not in WEIGHTINGS:
        raise ValidationInputError(f"weighting: expected one of {', '.join(WEIGHTINGS)}, got {weighting!r}")
    centre = e.mean(axis=-2, keepdims=True) if weighting == "dd" else e[..., :1, :]
    d = e - centre
    return np.einsum("...ni,...nj->...ij", d, d)
