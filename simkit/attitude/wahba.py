"""Attitude from fixed baselines, with covariance: SVD (Wahba), Badshah 2015 eq 10, single baseline.

Frames: baselines ``b`` in ENU (m), body baselines ``F`` (3, r) in the body frame (x right, y forward, z up);
R = C_b^n body -> ENU. Attitude error phi (rad) is the small rotation in ENU with R_true = exp([phi x]) R, so a
baseline moves by db = -[(R f) x] phi; its covariance is (H' Qb^-1 H)^-1 with H = [-[(R f_j) x]]_j (3 r, 3) and
Qb the fixed-baseline covariance. Euler [pitch, roll, heading] covariances are J P J' with J = d euler / d phi.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ..frames import euler_jacobian, skew, wrap_2pi
from ..validation import atdop as validation_atdop


def _proper(U, Vt):
    """U diag(1, 1, det(U V')) V' (K, 3, 3): the nearest rotation."""
    s = np.ones(U.shape[:-1])
    s[..., 2] = np.sign(np.linalg.det(U @ Vt))
    return (U * s[..., None, :]) @ Vt


def wahba_svd(b: np.ndarray, F: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """R (K, 3, 3) minimising sum_j w_j |b_j - R f_j|^2: ``b`` (K, 3, r) m ENU, ``F`` (3, r) m body, ``weights``
    (K, r) (1 when None). Needs r >= 2 non-parallel baselines."""
    w = np.ones(b.shape[::2]) if weights is None else weights
    B = np.einsum("kij,kj,lj->kil", b, w, F)
    U, _, Vt = np.linalg.svd(B)
    return _proper(U, Vt)


def badshah_eq10(b: np.ndarray, F: np.ndarray) -> np.ndarray:
    """C_b^n = r^n (r^b)' [r^b (r^b)']^-1 (Badshah 2015 eq 10), then orthonormalised (nearest rotation).

    ``b`` (K, 3, r), ``F`` (3, r). With r = 2 the third column is b1 x b2 in both frames (Badshah eqs 6-7).
    """
    if F.shape[1] == 2:
        F = np.column_stack([F, np.cross(F[:, 0], F[:, 1])])
        b = np.concatenate([b, np.cross(b[:, :, 0], b[:, :, 1])[:, :, None]], axis=2)
    C = b @ F.T @ np.linalg.inv(F @ F.T)
    U, _, Vt = np.linalg.svd(C)
    return _proper(U, Vt)


def phi_covariance(R: np.ndarray, F: np.ndarray, Qb: np.ndarray) -> np.ndarray:
    """Covariance (K, 3, 3) rad^2 of the ENU attitude error phi given baseline covariance Qb (K, 3 r, 3 r) m^2."""
    H = -skew(np.einsum("kij,jr->kri", R, F)).reshape(R.shape[0], -1, 3)  # (K, 3 r, 3)
    N = np.swapaxes(H, 1, 2) @ np.linalg.solve(Qb, H)
    return np.linalg.inv(N)


def euler_covariance(R: np.ndarray, P_phi: np.ndarray) -> np.ndarray:
    """Covariance (K, 3, 3) rad^2 of [pitch, roll, heading] from the ENU attitude-error covariance."""
    J = euler_jacobian(Rotation.from_matrix(R))
    return J @ P_phi @ np.swapaxes(J, 1, 2)


def single_baseline(b: np.ndarray, Qb: np.ndarray, f: np.ndarray):
    """Heading and pitch of one baseline: ``b`` (K, 3) m ENU, ``Qb`` (K, 3, 3), ``f`` (3,) body baseline.

    heading = azimuth(b) - azimuth(f), pitch = elevation(b) - elevation(f) (azimuth clockwise from north /
    from body y; exact for a forward baseline). Returns (pitch (K,), heading (K,) in [0, 2 pi), cov (K, 2, 2)).
    """
    e, n, u = b[:, 0], b[:, 1], b[:, 2]
    h2 = e * e + n * n
    az_b, el_b = np.arctan2(f[0], f[1]), np.arctan2(f[2], np.hypot(f[0], f[1]))
    heading = wrap_2pi(np.arctan2(e, n) - az_b)
    pitch = np.arctan2(u, np.sqrt(h2)) - el_b
    l2, h = h2 + u * u, np.sqrt(h2)
    J = np.zeros((len(b), 2, 3))
    J[:, 0] = np.stack([-e * u / (h * l2), -n * u / (h * l2), h / l2], -1)
    J[:, 1] = np.stack([n / h2, -e / h2, np.zeros_like(e)], -1)
    return pitch, heading, J @ Qb @ np.swapaxes(J, 1, 2)


def euler_atdop(R: np.ndarray, F: np.ndarray, G: np.ndarray, Q: np.ndarray | None = None) -> np.ndarray:
    """ATDOP (K, 3) [pitch, roll, heading] rad per metre of DD carrier noise: sqrt(diag(J L^-1 J')) with the
    Gramian L = H' H of the DD carrier rows H = G [-(R f_k) x] (unit weights; Wang 2018 eqs 8, 10-12, 16),
    through :func:`simkit.validation.atdop` of the Gramian in Euler coordinates, (J L^-1 J')^-1.
    ``G`` (K, n, 3) DD geometry of one baseline's channels (the same for every baseline). With ``Q`` (K, r n,
    r n) the DD carrier covariance (m^2), the weighted ATDOP: L = H' (Q / s^2)^-1 H with s^2 the mean diagonal
    of Q, so that ATDOP x s is the attitude sd of the weighted fit (elevation weighting and DD correlations
    included) and the unit-weight ATDOP is the case Q = s^2 I."""
    H = np.concatenate([G @ -skew(np.einsum("kij,j->ki", R, F[:, k])) for k in range(F.shape[1])], axis=1)
    if Q is None:
        L = np.swapaxes(H, 1, 2) @ H
    else:
        s2 = np.mean(np.diagonal(Q, axis1=1, axis2=2), axis=1)[:, None, None]
        L = np.swapaxes(H, 1, 2) @ np.linalg.solve(Q / s2, H)
    Ji = np.linalg.inv(euler_jacobian(Rotation.from_matrix(R)))
    return validation_atdop(np.swapaxes(Ji, 1, 2) @ L @ Ji)


def wahba_wls(b: np.ndarray, F: np.ndarray, Qb: np.ndarray, iterations: int = 3) -> np.ndarray:
    """Full-weight attitude: min_R (b - vec(R F))' Qb^-1 (b - vec(R F)), from the SVD solution by Gauss-Newton
    on SO(3). ``b`` (K, 3, r) m ENU, ``Qb`` (K, 3 r, 3 r) m^2 (baseline-major). Its covariance is
    :func:`phi_covariance` (the estimator is efficient to first order)."""
    K, r = b.shape[0], F.shape[1]
    R = wahba_svd(b, F)
    y = b.transpose(0, 2, 1).reshape(K, 3 * r)
    for _ in range(iterations):
        RF = np.einsum("kij,jr->kri", R, F)
        H = -skew(RF).reshape(K, 3 * r, 3)
        WH = np.linalg.solve(Qb, H)
        g = np.einsum("kri,kr->ki", WH, y - RF.reshape(K, -1))
        phi = np.linalg.solve(np.swapaxes(H, 1, 2) @ WH, g[..., None])[..., 0]
        R = Rotation.from_rotvec(phi).as_matrix() @ R
    return R


def propagated_covariance(estimator, b: np.ndarray, Qb: np.ndarray, eps: float = 1e-6) -> np.ndarray:
    """Covariance (K, 3, 3) rad^2 of the ENU attitude error of ``estimator(b) -> R`` (b (K, 3, r) -> (K, 3, 3)),
    J Qb J' with J = d phi / d vec(b) by central differences (so each estimator's own linearisation is used)."""
    K, _, r = b.shape
    R0 = estimator(b)
    J = np.empty((K, 3, 3 * r))
    for j in range(r):
        for i in range(3):
            step = np.zeros_like(b)
            step[:, i, j] = eps
            hi, lo = estimator(b + step), estimator(b - step)
            J[:, :, 3 * j + i] = (Rotation.from_matrix(hi @ np.swapaxes(R0, 1, 2)).as_rotvec()
                                  - Rotation.from_matrix(lo @ np.swapaxes(R0, 1, 2)).as_rotvec()) / (2 * eps)
    return J @ Qb @ np.swapaxes(J, 1, 2)
