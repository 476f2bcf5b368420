"""Pure filter kernels: covariance propagation, the Kalman correction (Joseph form) and the H-infinity correction
(Simon 2006 ch. 11, game-theory form; Wu 2015 eq 17 with L = I), each numba-compiled and free of state.

Kalman:  S = H P H^T + R,  K = P H^T S^-1,  x = x + K nu,  P = (I - K H) P (I - K H)^T + K R K^T;
         NIS = nu^T S^-1 nu; standardised innovations w = L^-1 nu with S = L L^T (N(0, I) when consistent).
H-infinity (theta = gamma^-2):
         A = I - theta P + H^T R^-1 H P,  K = P A^-1 H^T R^-1,  x = x + K nu,  P = P A^-1,
         existence: P^-1 - theta I + H^T R^-1 H > 0 (its smallest eigenvalue is recorded as the margin);
         gamma adapts as in Wu 2015: gamma^2 = alpha * max eig((P^-1 + H^T H)^-1), alpha > 1.
         When the margin is not positive, theta is lowered to half the smallest eigenvalue of P^-1 + H^T R^-1 H
         (gamma raised) so that it is, and the status records it: the condition is never violated silently.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

STATUS_OK = 0
STATUS_GAMMA_RAISED = 1      # H-infinity: the adaptive gamma violated the existence condition; gamma was raised
STATUS_S_NOT_PD = 2          # innovation covariance not positive definite: update skipped


@njit(cache=True)
def propagate(x, p, phi, qd):
    """x = Phi x, P = Phi P Phi^T + Q_d (symmetrised)."""
    p = phi @ p @ phi.T + qd
    return phi @ x, 0.5 * (p + p.T)


@njit(cache=True)
def _chol(s):
    """Cholesky factor, or an empty matrix when ``s`` is not positive definite."""
    n = s.shape[0]
    l = np.zeros((n, n))
    for j in range(n):
        d = s[j, j] - np.sum(l[j, :j] ** 2)
        if not d > 0.0:
            return np.zeros((0, 0))
        l[j, j] = np.sqrt(d)
        for i in range(j + 1, n):
            l[i, j] = (s[i, j] - np.sum(l[i, :j] * l[j, :j])) / l[j, j]
    return l


@njit(cache=True)
def correct(x, p, nu, h, r):
    """Kalman correction with innovation ``nu`` = z - H x. Returns (x, P, nis, w standardised, status)."""
    s = h @ p @ h.T + r
    l = _chol(s)
    m = nu.size
    if l.shape[0] == 0:
        return x, p, np.nan, np.full(m, np.nan), STATUS_S_NOT_PD
    w = np.linalg.solve(l, nu)
    k = np.linalg.solve(s, h @ p).T
    ikh = np.eye(p.shape[0]) - k @ h
    p_new = ikh @ p @ ikh.T + k @ r @ k.T
    return x + k @ nu, 0.5 * (p_new + p_new.T), np.sum(w * w), w, STATUS_OK


@njit(cache=True)
def hinf_gamma(p_inv, h, alpha):
    """Wu 2015's adaptive gamma: sqrt(alpha * max eig((P^-1 + H^T H)^-1))."""
    lam = np.linalg.eigvalsh(p_inv + h.T @ h)
    return np.sqrt(alpha / lam[0])


@njit(cache=True)
def correct_hinf(x, p, nu, h, r, alpha):
    """H-infinity correction. Returns (x, P, nis, w, gamma, margin, status); see the module docstring."""
    n = p.shape[0]
    p_inv = np.linalg.inv(p)
    p_inv = 0.5 * (p_inv + p_inv.T)
    r_inv = np.linalg.inv(r)
    hrh = h.T @ r_inv @ h
    gamma = hinf_gamma(p_inv, h, alpha)
    theta = 1.0 / gamma**2
    margin = np.linalg.eigvalsh(p_inv - theta * np.eye(n) + hrh)[0]
    status = STATUS_OK
    if not margin > 0.0:
        theta = 0.5 * np.linalg.eigvalsh(p_inv + hrh)[0]
        gamma = 1.0 / np.sqrt(theta)
        margin = np.linalg.eigvalsh(p_inv - theta * np.eye(n) + hrh)[0]
        status = STATUS_GAMMA_RAISED
    s = h @ p @ h.T + r
    l = _chol(s)
    if l.shape[0] == 0 or not margin > 0.0:
        return x, p, np.nan, np.full(nu.size, np.nan), gamma, margin, STATUS_S_NOT_PD
    w = np.linalg.solve(l, nu)
    a_inv = np.linalg.inv(np.eye(n) - theta * p + hrh @ p)
    k = p @ a_inv @ h.T @ r_inv
    p_new = p @ a_inv
    return x + k @ nu, 0.5 * (p_new + p_new.T), np.sum(w * w), w, gamma, margin, status


@dataclass(frozen=True)
class Correction:
    """One measurement update: state ``x`` (n,), covariance ``P`` (n, n), innovation ``nu`` (m,) and its
    covariance ``S`` (m, m), ``nis`` = nu^T S^-1 nu, ``status`` (0 ok; see STATUS_*)."""

    x: np.ndarray
    P: np.ndarray
    nu: np.ndarray
    S: np.ndarray
    nis: float
    status: int


def kalman_update(x, P, z, H, R) -> Correction:
    """Pure Kalman correction for measurement ``z`` (m,) = H x + v, v ~ N(0, R); Joseph form."""
    x, P, z, H, R = (np.asarray(a, dtype=float) for a in (x, P, z, H, R))
    nu = z - H @ x
    xn, pn, nis, _, status = correct(x, P, nu, H, R)
    return Correction(xn, pn, nu, H @ P @ H.T + R, float(nis), int(status))
