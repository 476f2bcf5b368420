"""Inner problems of the baseline-constrained ILS: the best baseline(s) for given integer ambiguities.

Both minimise ``(c - x)^T W (c - x)`` where ``c`` is the ambiguity-conditioned float baseline (m) and ``W`` its
weight matrix (1/m^2):

- :func:`sphere_fit`: ``x = b`` with ``|b| = l`` (one baseline of known length, C-LAMBDA, Teunissen 2010). Solved
  exactly with the Lagrange multiplier: ``b = (W + lam I)^{-1} W c`` with the unique ``lam > -w_min`` on the secular
  equation ``|b(lam)| = l``, which gives the global minimum (as for the trust-region subproblem).
- :func:`rotation_fit`: ``x = vec(R F)`` with ``R`` in SO(3) and known body-frame baselines ``F`` (3, r)
  (multivariate constrained LAMBDA, Giorgi et al. 2010/2012). Started from the orthogonal Procrustes solution (SVD)
  and refined by Gauss-Newton on SO(3) with the full weight matrix.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _secular_norm(g, w, lam):
    s = 0.0
    for i in range(g.shape[0]):
        t = g[i] / (w[i] + lam)
        s += t * t
    return math.sqrt(s)


@njit(cache=True)
def _hard_case(g, w, cp, length, bp):
    """The hard case of the trust-region-like problem (``g`` has no component along the weakest axis and the
    rest of the solution lies inside the sphere): fill ``bp`` and return True, else return False."""
    p = g.shape[0]
    rest = 0.0
    for i in range(1, p):
        if w[i] > w[0]:
            t = g[i] / (w[i] - w[0])
            rest += t * t
    if rest > length * length:
        return False
    for i in range(1, p):
        bp[i] = g[i] / (w[i] - w[0]) if w[i] > w[0] else 0.0
    bp[0] = math.copysign(math.sqrt(length * length - rest), cp[0])
    return True


@njit(cache=True)
def _secular_root(g, w, length, lo, hi):
    """The multiplier ``lam`` in (lo, hi) with ``|b(lam)| = length``: Newton on 1/h(lam) - 1/length (nearly
    linear in lam), safeguarded by bisection."""
    p = g.shape[0]
    lam = hi
    for _ in range(100):
        h = _secular_norm(g, w, lam)
        if abs(h - length) <= 1e-15 * length:
            break
        if h > length:
            lo = lam
        else:
            hi = lam
        s3 = 0.0
        for i in range(p):
            t = w[i] + lam
            s3 += g[i] * g[i] / (t * t * t)
        step = (1.0 / h - 1.0 / length) * h * h * h / s3
        nxt = lam - step
        if not (lo < nxt < hi):
            nxt = 0.5 * (lo + hi)
        if nxt == lam or hi - lo <= 1e-15 * (abs(lo) + abs(hi)):
            break
        lam = nxt
    return lam


@njit(cache=True)
def sphere_fit(c, U, w, length, out):
    """Minimise ``(c - b)^T W (c - b)`` subject to ``|b| = length``; ``W = U diag(w) U^T``, ``w`` ascending > 0.

    Writes the minimiser into ``out`` (3,) and returns the minimum (dimensionless when W is in 1/m^2).
    """
    p = c.shape[0]
    cp = np.zeros(p)
    for i in range(p):
        for k in range(p):
            cp[i] += U[k, i] * c[k]
    g = w * cp
    gn = math.sqrt(np.sum(g * g))
    bp = np.zeros(p)
    if gn == 0.0:  # c = 0: every point of the sphere is at the same W-distance along the weakest axis
        bp[0] = length
    else:
        lo = max(-w[0], gn / length - w[p - 1])
        hi = gn / length - w[0]
        hard = lo == -w[0] and abs(g[0]) <= 1e-13 * gn and _hard_case(g, w, cp, length, bp)
        if not hard:
            lam = _secular_root(g, w, length, lo, hi)
            for i in range(p):
                bp[i] = g[i] / (w[i] + lam)
    cost = 0.0
    for i in range(p):
        r = cp[i] - bp[i]
        cost += w[i] * r * r
    for k in range(p):
        s = 0.0
        for i in range(p):
            s += U[k, i] * bp[i]
        out[k] = s
    return cost


@njit(cache=True)
def _rodrigues(theta):
    ang = math.sqrt(theta[0] ** 2 + theta[1] ** 2 + theta[2] ** 2)
    K = np.array([[0.0, -theta[2], theta[1]], [theta[2], 0.0, -theta[0]], [-theta[1], theta[0], 0.0]])
    if ang < 1e-300:
        return np.eye(3)
    return np.eye(3) + (math.sin(ang) / ang) * K + ((1.0 - math.cos(ang)) / (ang * ang)) * (K @ K)


@njit(cache=True)
def _residual(c, R, F):
    r = F.shape[1]
    res = np.empty(3 * r)
    for j in range(r):
        for k in range(3):
            res[3 * j + k] = c[3 * j + k] - (R[k, 0] * F[0, j] + R[k, 1] * F[1, j] + R[k, 2] * F[2, j])
    return res


@njit(cache=True)
def rotation_fit(c, W, F, out):
    """Minimise ``(c - vec(R F))^T W (c - vec(R F))`` over rotations ``R`` (body -> local frame).

    ``c`` (3r,) stacks the baselines ``[b_1; b_2; ...]`` (m), ``F`` (3, r) holds them in the body frame (m), ``W``
    (3r, 3r) is the weight matrix. Writes R row-major into ``out`` (9,) and returns the minimum.
    """
    r = F.shape[1]
    M = np.zeros((3, 3))
    for j in range(r):
        for a in range(3):
            for b in range(3):
                M[a, b] += c[3 * j + a] * F[b, j]
    Us, _, Vt = np.linalg.svd(M)
    D = np.eye(3)
    D[2, 2] = np.linalg.det(Us @ Vt)
    R = Us @ D @ Vt
    damp = 1e-12 * np.trace(W)
    J = np.empty((3 * r, 3))
    for _ in range(50):
        res = _residual(c, R, F)
        for j in range(r):
            f = F[:, j]
            Fx = np.array([[0.0, -f[2], f[1]], [f[2], 0.0, -f[0]], [-f[1], f[0], 0.0]])
            J[3 * j:3 * j + 3, :] = R @ Fx
        WJ = W @ J
        H = J.T @ WJ + damp * np.eye(3)
        theta = -np.linalg.solve(H, WJ.T @ res)
        R = R @ _rodrigues(theta)
        if math.sqrt(np.sum(theta * theta)) < 1e-13:
            break
    res = _residual(c, R, F)
    for a in range(3):
        for b in range(3):
            out[3 * a + b] = R[a, b]
    return res @ (W @ res)
