"""Pure filter kernels: covariance propagation, the Kalman correction (Joseph form) and the H-infinity correction
(Simon 2006 ch. 11, game-theory form; Wu 2015 eq 17 with L = I), each numba-compiled and free of state.

Kalman:  S = H P H^T + R,  K = P H^T S^-1,  x = x + K nu,  P = (I - K H) P (I - K H)^T + K R K^T;
         NIS = nu^T S^-1 nu; standardised innovations w = L^-1 nu with S = L L^T (N(0, I) when consistent).
H-infinity (theta = gamma^-2):
         A = I - theta P + H^T R^-1 H P,  K = P A^-1 H^T R^-1,  x = x + K nu,  P = P A^-1,
         existence: P^-1 - theta I + H^T R^-1 H > 0 (its smallest eigenvalue is recorded as the margin);
         gamma adapts as in Wu 2015: gamma^2 = alpha * max eig((P^-1 + H^T H)^-1), alpha > 1.
         P+ = (P^-1 - theta I + H^T R^-1 H)^-1 is computed through the Cholesky factor of P (see _existence).
         Wu's gamma uses the unweighted H^T H, so it depends on the state and measurement units: with R > 1 (e.g.
         a height fix of 5 m sigma) it can violate the condition, or pass it by a hair (margin 1e-4: P and the
         gain grow 1e4-fold in one direction, and the estimate spikes by kilometres). Wu's theta is therefore
         used only while it is at most the weighted rule's theta = 1 / (alpha max eig((P^-1 + H^T R^-1 H)^-1))
         (the inverse is the Kalman posterior P_kf): that keeps P+ <= alpha / (alpha - 1) P_kf, a margin of
         1 - 1/alpha in the existence matrix normalised by I + (HL)^T R^-1 HL. Otherwise gamma is raised to the
         weighted rule and the status records it: the condition is never violated or nearly violated silently.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

STATUS_OK = 0
STATUS_GAMMA_RAISED = 1      # H-infinity: Wu's gamma would violate (or nearly) the existence condition; raised
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
def _lower_solve(l, b):
    """L^-1 B for lower-triangular ``l`` (m, m) and ``b`` (m, k), by forward substitution."""
    m, k = b.shape
    y = np.empty((m, k))
    for i in range(m):
        for j in range(k):
            acc = b[i, j]
            for q in range(i):
                acc -= l[i, q] * y[q, j]
            y[i, j] = acc / l[i, i]
    return y


@njit(cache=True)
def _upper_solve(l, b):
    """L^-T B for lower-triangular ``l`` (m, m) and ``b`` (m, k), by back substitution."""
    m, k = b.shape
    y = np.empty((m, k))
    for i in range(m - 1, -1, -1):
        for j in range(k):
            acc = b[i, j]
            for q in range(i + 1, m):
                acc -= l[q, i] * y[q, j]
            y[i, j] = acc / l[i, i]
    return y


@njit(cache=True)
def chol_solve(l, b):
    """S^-1 B for S = L L^T (``l`` its Cholesky factor), ``b`` (m, k). Hand-written (with :func:`_chol`) so that
    the filter loop instantiates no LAPACK wrapper: those dominate numba's compile time."""
    return _upper_solve(l, _lower_solve(l, b))


@njit(cache=True)
def correct(x, p, nu, h, r):
    """Kalman correction with innovation ``nu`` = z - H x. Returns (x, P, nis, w standardised, status)."""
    s = h @ p @ h.T + r
    l = _chol(s)
    m = nu.size
    if l.shape[0] == 0:
        return x, p, np.nan, np.full(m, np.nan), STATUS_S_NOT_PD
    w = _lower_solve(l, nu.reshape((m, 1)))[:, 0]
    k = chol_solve(l, h @ p).T
    ikh = np.eye(p.shape[0]) - k @ h
    p_new = ikh @ p @ ikh.T + k @ r @ k.T
    return x + k @ nu, 0.5 * (p_new + p_new.T), np.sum(w * w), w, STATUS_OK


@njit(cache=True)
def hinf_gamma(p, h, alpha):
    """Wu 2015's adaptive gamma: sqrt(alpha * max eig((P^-1 + H^T H)^-1)), with (P^-1 + H^T H)^-1 formed as
    P - P H^T (I + H P H^T)^-1 H P (matrix inversion lemma: no inverse of the ill-scaled P)."""
    hp = h @ p
    m = p - hp.T @ chol_solve(_chol(np.eye(h.shape[0]) + hp @ h.T), hp)
    return np.sqrt(alpha * np.linalg.eigvalsh(0.5 * (m + m.T))[-1])


@njit(cache=True)
def _existence(l, h, r_inv, theta):
    """L^T (P^-1 - theta I + H^T R^-1 H) L = I - theta L^T L + (H L)^T R^-1 (H L) for P = L L^T: congruent to the
    existence matrix (same inertia, Sylvester), but well scaled whatever the state units."""
    hl = h @ l
    e = np.eye(l.shape[0]) - theta * (l.T @ l) + hl.T @ r_inv @ hl
    return 0.5 * (e + e.T)


@njit(cache=True)
def weighted_theta(p, h, r, alpha):
    """theta = 1 / (alpha * max eig((P^-1 + H^T R^-1 H)^-1)): Wu's rule with the measurement weighting (the
    inverse is the Kalman posterior covariance, formed in Joseph form). The existence matrix then stays
    positive definite by construction, and no direction of P grows by more than alpha / (alpha - 1) per update."""
    _, p_kf, _, _, status = correct(np.zeros(p.shape[0]), p, np.zeros(h.shape[0]), h, r)
    if status != STATUS_OK:
        return np.nan
    return 1.0 / (alpha * np.linalg.eigvalsh(p_kf)[-1])


@njit(cache=True)
def correct_hinf(x, p, nu, h, r, alpha, weighted=False):
    """H-infinity correction. Returns (x, P, nis, w, gamma, margin, status); see the module docstring. The
    margin is the smallest eigenvalue of the congruent, dimensionless form of the existence matrix. With
    ``weighted`` the gamma rule uses H^T R^-1 H instead of Wu's H^T H (see :func:`weighted_theta`); without it,
    Wu's theta is used only where it is at most the weighted theta, which bounds the growth of P over the Kalman
    posterior by alpha / (alpha - 1) (a margin of 1 - 1/alpha). Merely existing is not enough: a margin of 1e-4
    passes the condition but multiplies a direction of P by 1e4 and the update's gain with it."""
    l = _chol(p)
    ls = _chol(h @ p @ h.T + r)
    if l.shape[0] == 0 or ls.shape[0] == 0:
        return x, p, np.nan, np.full(nu.size, np.nan), np.nan, np.nan, STATUS_S_NOT_PD
    r_inv = chol_solve(_chol(r), np.eye(r.shape[0]))
    theta = weighted_theta(p, h, r, alpha)
    status = STATUS_OK
    if not weighted:
        theta_wu = 1.0 / hinf_gamma(p, h, alpha) ** 2
        if theta_wu <= theta:
            theta = theta_wu
        else:  # Wu's rule would leave the update (nearly) singular: the weighted rule's margin instead
            status = STATUS_GAMMA_RAISED
    margin = np.linalg.eigvalsh(_existence(l, h, r_inv, theta))[0]
    while not margin > 0.0 and theta > 1e-300:  # rounding only: the weighted rule keeps margin >= 1 - 1/alpha
        status = STATUS_GAMMA_RAISED
        theta *= 0.5
        margin = np.linalg.eigvalsh(_existence(l, h, r_inv, theta))[0]
    e = _existence(l, h, r_inv, theta)
    p_new = l @ chol_solve(_chol(e), l.T.copy())
    p_new = 0.5 * (p_new + p_new.T)
    k = p_new @ h.T @ r_inv
    w = _lower_solve(ls, nu.reshape((nu.size, 1)))[:, 0]
    return x + k @ nu, p_new, np.sum(w * w), w, 1.0 / np.sqrt(theta), margin, status


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
