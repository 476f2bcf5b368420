"""Penalised quintic smoothing splines (P-splines) for noisy samples of a smooth curve, with exact derivatives.

The curve is a quintic B-spline on uniformly spaced knots (the median sample interval, so about one coefficient
per sample). Its coefficients c minimise

    sum_i w_i (y_i - s(t_i))^2  +  sum_j u_j (v_j - s'(t_j))^2  +  lam * |D3 c|^2

with weights w = 1/sigma^2 of the values and u = 1/sigma_v^2 of optional derivative samples, and D3 the
third-order difference operator (Eilers & Marx 1996, "Flexible smoothing with B-splines and penalties"): on
uniform knots |D3 c|^2 is proportional to the integral of the squared third derivative, the penalty whose
minimiser is the quintic smoothing spline. A quintic is C4, so velocity is C3, acceleration C2 and jerk C1:
specific force and body rates built from them have no steps at the samples.

The smoothness ``lam`` follows the noise (discrepancy principle): the largest ``lam`` whose weighted residual sum
of squares does not exceed the number of samples, the value expected when the residuals are the noise (the same
rule as FITPACK's smoothing factor s = m with weights 1/sigma). Gaps between samples are bridged by the penalty
(the curve of least jerk); the null space of the penalty is a quadratic, so a curve needs at least 3 samples.
"""
from __future__ import annotations

import numpy as np
from scipy.interpolate import BSpline
from scipy.linalg import LinAlgError, solveh_banded
from scipy import sparse

DEGREE = 5
_LOG_LAM = (-10.0, 12.0)
_BISECTIONS = 48


def _difference(n: int, order: int) -> sparse.csr_matrix:
    d = sparse.eye(n, format="csr")
    for _ in range(order):
        d = d[1:] - d[:-1]
    return d


def _banded(m: sparse.spmatrix, u: int) -> np.ndarray:
    """Upper banded storage of a symmetric sparse matrix with ``u`` super-diagonals (``solveh_banded`` form)."""
    m = m.tocoo()
    keep = (m.col >= m.row) & (m.col - m.row <= u)
    ab = np.zeros((u + 1, m.shape[0]))
    np.add.at(ab, (u + m.row[keep] - m.col[keep], m.col[keep]), m.data[keep])
    return ab


def knots(t_min: float, t_max: float, spacing: float) -> np.ndarray:
    """Uniform knots of ``spacing`` (s) covering [t_min, t_max], extended by ``DEGREE`` knots on each side."""
    n = max(1, int(np.ceil((t_max - t_min) / spacing - 1e-9)))
    h = (t_max - t_min) / n
    return t_min + h * np.arange(-DEGREE, n + DEGREE + 1)


def _design(t, x, nu: int) -> sparse.csr_matrix:
    """Rows: the ``nu``-th derivative of every basis function at ``x``."""
    if nu == 0:
        return BSpline.design_matrix(x, t, DEGREE)
    lower = BSpline.design_matrix(x, t[1:-1], DEGREE - 1)
    n = len(t) - DEGREE - 1
    scale = DEGREE / (t[DEGREE + 1:DEGREE + n] - t[1:n])
    diff = sparse.diags([-scale, scale], [0, 1], shape=(n - 1, n), format="csr")
    return lower @ diff


def smooth(t_knots, x, y, sigma, xv=None, v=None, sigma_v=None) -> tuple[BSpline, float, float]:
    """The P-spline through values ``y`` at ``x`` (standard deviations ``sigma``, each (K,)) and optional slopes
    ``v`` at ``xv`` (``sigma_v``); returns (spline, lam, weighted residual sum of squares).

    ``x`` and ``xv`` must lie within the base interval of ``t_knots`` (:func:`knots`).
    """
    rows = [(_design(t_knots, x, 0), np.asarray(y, float), 1.0 / np.asarray(sigma, float) ** 2)]
    if v is not None:
        rows.append((_design(t_knots, xv, 1), np.asarray(v, float), 1.0 / np.asarray(sigma_v, float) ** 2))
    n = len(t_knots) - DEGREE - 1
    normal = sum(b.T @ sparse.diags(w) @ b for b, _, w in rows)
    rhs = sum(b.T @ (w * obs) for b, obs, w in rows)
    d3 = _difference(n, 3)
    a_band, p_band = _banded(normal, DEGREE), _banded(d3.T @ d3, DEGREE)
    scale = np.mean(a_band[-1]) / max(np.mean(p_band[-1]), 1e-300)
    target = float(sum(len(obs) for _, obs, _ in rows))

    def solve(log_lam):
        ab = a_band + 10.0 ** log_lam * scale * p_band
        c = solveh_banded(ab, rhs, check_finite=False)
        rss = float(sum(np.sum(w * (obs - b @ c) ** 2) for b, obs, w in rows))
        return c, rss

    lo, hi = _LOG_LAM
    # at the extremes the system can be numerically singular (a penalty too weak for more coefficients than
    # samples, or too strong beside the data): step inwards until it solves
    while True:
        try:
            c_hi, rss_hi = solve(hi)
            break
        except LinAlgError:
            hi -= 1.0
    if rss_hi <= target:          # a quadratic already fits within the noise
        return BSpline(t_knots, c_hi, DEGREE), 10.0 ** hi * scale, rss_hi
    while True:
        try:
            best = solve(lo)
            break
        except LinAlgError:
            lo += 1.0
            if lo >= hi:
                raise
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        c, rss = solve(mid)
        if rss <= target:
            lo, best = mid, (c, rss)
        else:
            hi = mid
    return BSpline(t_knots, best[0], DEGREE), 10.0 ** lo * scale, best[1]


def noise_sigma(t, y) -> float:
    """Noise standard deviation of samples ``y`` of a smooth curve, from their third differences: for white noise
    var(D3 y) = 20 sigma^2 (coefficients 1, -3, 3, -1). A robust scale (1.4826 MAD) first sets aside the few
    differences a manoeuvre dominates (beyond 4 of its sigmas); the RMS of the rest gives the estimate. Only runs of four near-uniformly spaced samples (intervals within 10 %) are used; NaN
    when there are none."""
    dt = np.diff(t)
    uniform = (np.abs(dt[1:] / dt[:-1] - 1.0) < 0.1)
    ok = uniform[1:] & uniform[:-1]
    d3 = np.diff(y, 3)[ok]
    if d3.size == 0:
        return float("nan")
    rough = 1.4826 * np.median(np.abs(d3 - np.median(d3)))
    inliers = d3[np.abs(d3) <= 4.0 * rough]        # then the efficient RMS of the differences within 4 sigma
    return float(np.sqrt(np.mean(inliers**2) / 20.0)) if inliers.size else float("nan")
