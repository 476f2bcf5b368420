"""Overlapping Allan deviation, the IEEE Std 952 noise-term models, and a fit recovering them from data.

Terms (two-sided PSD convention), Allan variance as a function of the averaging time tau:
  Q quantization        3 Q^2 / tau^2          (Q = increment LSB / sqrt(12); rad or m/s)
  N angle/velocity RW   N^2 / tau              (rad/sqrt(s) or m/s/sqrt(s))
  B bias instability    (2 ln 2 / pi) B^2      (floor 0.664 B; rad/s or m/s^2)
  K rate random walk    K^2 tau / 3            (rad/s/sqrt(s) or m/s^2/sqrt(s))
  R rate ramp           R^2 tau^2 / 2          (rad/s^2 or m/s^3)
  Gauss-Markov (sigma, T): (2 sigma^2 T / tau) [1 - T / (2 tau) (3 - 4 exp(-tau/T) + exp(-2 tau/T))]
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize

FLICKER_FLOOR = math.sqrt(2.0 * math.log(2.0) / math.pi)  # 0.6643: ADEV floor per unit IEEE B
TERMS = ("Q", "N", "B", "K", "R")


def default_multiples(n: int, per_decade: int = 10) -> np.ndarray:
    """The averaging times, in samples, of :func:`adev` by default for ``n`` samples: ``per_decade`` log-spaced
    whole multiples m of the interval, 1 <= m <= (n - 1) / 2 (n >= 3)."""
    m_max = (n - 1) // 2
    grid = np.logspace(0, math.log10(m_max), max(2, int(per_decade * math.log10(m_max)) + 1))
    return np.unique(np.round(grid)).astype(np.int64)


def adev(y: np.ndarray, dt: float, taus=None, per_decade: int = 10):
    """Overlapping Allan deviation of rate samples ``y`` ((N,) or (N, k), one series per column) at interval dt.

    ``taus`` (s) are rounded to whole multiples m of dt with 1 <= m <= (N - 1) / 2; by default ``per_decade``
    log-spaced values. Returns ``(taus, adev, counts)``: adev has shape (T,) or (T, k); counts are the numbers
    of overlapping second differences behind each value. Cumulative-sum based: O(N) per tau.
    """
    y = np.asarray(y, dtype=float)
    flat = y.ndim == 1
    y2 = y[:, None] if flat else y
    n = y2.shape[0]
    if n < 3:
        raise ValueError("need at least 3 samples for an Allan deviation")
    if taus is None:
        m = default_multiples(n, per_decade)
    else:
        m = np.unique(np.clip(np.round(np.asarray(taus, dtype=float) / dt), 1, (n - 1) // 2)).astype(np.int64)
    x = np.zeros((n + 1, y2.shape[1]))
    np.cumsum(y2 - y2.mean(axis=0), axis=0, out=x[1:])
    out = np.empty((m.size, y2.shape[1]))
    for i, mi in enumerate(m):
        d = x[2 * mi:] - 2.0 * x[mi:n + 1 - mi] + x[:n + 1 - 2 * mi]
        out[i] = np.sqrt(np.einsum("ij,ij->j", d, d) / (d.shape[0] * 2.0 * float(mi) ** 2))
    return m * dt, (out[:, 0] if flat else out), n + 1 - 2 * m


def gm_avar(tau, sigma: float, t_corr: float):
    """Allan variance of a first-order Gauss-Markov process of stationary std ``sigma`` and correlation time T."""
    x = np.asarray(tau, dtype=float) / t_corr
    return 2.0 * sigma**2 / x * (1.0 - (3.0 - 4.0 * np.exp(-x) + np.exp(-2.0 * x)) / (2.0 * x))


def gm_peak(sigma: float, t_corr: float) -> tuple[float, float]:
    """(tau, adev) at the maximum of a Gauss-Markov Allan deviation (tau ~ 1.89 T, adev ~ 0.62 sigma)."""
    r = optimize.minimize_scalar(lambda lx: -gm_avar(math.exp(lx), 1.0, 1.0), bounds=(-1, 3), method="bounded")
    return math.exp(r.x) * t_corr, math.sqrt(-r.fun) * sigma


def _basis(tau: np.ndarray, name: str) -> np.ndarray:
    return {"Q": 3.0 / tau**2, "N": 1.0 / tau, "B": np.full_like(tau, FLICKER_FLOOR**2),
            "K": tau / 3.0, "R": tau**2 / 2.0}[name]


@dataclass
class AllanFit:
    """Fitted IEEE coefficients (SI; 0 when absent) and Gauss-Markov terms [(sigma, T), ...]."""

    Q: float = 0.0
    N: float = 0.0
    B: float = 0.0
    K: float = 0.0
    R: float = 0.0
    gauss_markov: list = field(default_factory=list)
    rms_log_error: float = 0.0   # rms of ln(model adev / measured adev) over the fitted points

    def avar(self, tau) -> np.ndarray:
        tau = np.asarray(tau, dtype=float)
        v = sum(getattr(self, t) ** 2 * _basis(tau, t) for t in TERMS)
        for s, t in self.gauss_markov:
            v = v + gm_avar(tau, s, t)
        return v

    def adev(self, tau) -> np.ndarray:
        return np.sqrt(self.avar(tau))

    def as_dict(self) -> dict:
        return {"Q": self.Q, "N": self.N, "B": self.B, "K": self.K, "R": self.R,
                "gauss_markov": [{"sigma": s, "tau_s": t} for s, t in self.gauss_markov],
                "rms_log_error": self.rms_log_error}


def _nnls(tau, avar, weight, terms, gm_taus):
    cols = [_basis(tau, t) for t in terms] + [gm_avar(tau, 1.0, t) for t in gm_taus]
    a = np.stack(cols, axis=1) / avar[:, None] * weight[:, None]
    coef, resid = optimize.nnls(a, weight)
    return coef, resid


def fit(tau, adev_values, counts=None, terms=TERMS, n_gm: int = 0) -> AllanFit:
    """Fit the Allan deviation ``adev_values`` at ``tau`` with the IEEE terms ``terms`` and ``n_gm`` Gauss-Markov terms.

    Weighted non-negative least squares on the Allan variance in relative terms (each point weighted by the square
    root of its number of overlapping differences ``counts`` times tau^-1/2, a proxy of its equivalent degrees of
    freedom); Gauss-Markov correlation times by a log-grid search refined by a bounded scalar search.
    """
    tau = np.asarray(tau, dtype=float)
    avar = np.asarray(adev_values, dtype=float) ** 2
    ok = np.isfinite(avar) & (avar > 0)
    tau, avar = tau[ok], avar[ok]
    counts = np.ones_like(tau) if counts is None else np.asarray(counts, dtype=float)[ok]
    weight = np.sqrt(counts * tau[0] / tau)
    weight = weight / weight.max()
    terms = tuple(terms)
    best = (None, None, math.inf)
    if n_gm == 0:
        coef, resid = _nnls(tau, avar, weight, terms, ())
        best = (coef, (), resid)
    else:
        grid = np.logspace(math.log10(tau[0] / 2), math.log10(tau[-1]), 25)
        import itertools

        for combo in itertools.combinations(grid, n_gm):
            coef, resid = _nnls(tau, avar, weight, terms, combo)
            if resid < best[2]:
                best = (coef, combo, resid)
        gm_taus = list(best[1])
        step = grid[1] / grid[0]
        for i in range(n_gm):  # refine each correlation time in turn around its grid value
            def cost(lt, i=i):
                trial = gm_taus[:i] + [math.exp(lt)] + gm_taus[i + 1:]
                return _nnls(tau, avar, weight, terms, trial)[1]
            lo, hi = math.log(gm_taus[i] / step), math.log(gm_taus[i] * step)
            gm_taus[i] = math.exp(optimize.minimize_scalar(cost, bounds=(lo, hi), method="bounded").x)
        coef, resid = _nnls(tau, avar, weight, terms, gm_taus)
        best = (coef, tuple(gm_taus), resid)
    coef, gm_taus, _ = best
    result = AllanFit(**{t: math.sqrt(c) for t, c in zip(terms, coef[:len(terms)])})
    result.gauss_markov = [(math.sqrt(c), t) for c, t in zip(coef[len(terms):], gm_taus) if c > 0]
    result.rms_log_error = float(np.sqrt(np.mean(np.log(result.avar(tau) / avar) ** 2)) / 2.0)
    return result
