"""Success rates of integer estimation (Teunissen 1998, 1999, 2000; Verhagen 2005).

All take an ambiguity covariance (cycles^2). ``decorrelate_first`` chooses the parametrisation: bootstrapping and
the variance/eigenvalue bounds depend on it, the ILS and ADOP-based figures do not.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.special import erf, gammaln
from scipy.stats import chi2

from .decorrelation import decorrelate, ltdl
from .errors import AmbiguityInputError
from .estimators import bootstrap_z, round_half_up


def _cond_variances(Q, decorrelate_first):
    return decorrelate(Q).d if decorrelate_first else ltdl(Q)[1]


def _p1(var):
    """P(|e| < 1/2) for e ~ N(0, var): 2 Phi(1 / (2 sigma)) - 1."""
    return erf(1.0 / (2.0 * np.sqrt(2.0 * np.asarray(var, dtype=float))))


def bootstrap_success_rate(Q=None, d=None, decorrelate_first=True) -> float:
    """Exact success rate of integer bootstrapping: prod_i (2 Phi(1 / (2 sqrt(d_i))) - 1).

    Give ``Q`` (n, n), or the conditional variances ``d`` (n,) directly (or stacked (K, n): returns (K,)). With
    ``decorrelate_first`` it is also the sharpest easy lower bound of the ILS success rate (Teunissen 1999).
    """
    if d is None:
        d = _cond_variances(Q, decorrelate_first)
    p = np.prod(_p1(d), axis=-1)
    return float(p) if np.ndim(p) == 0 else p


def adop(Q) -> float:
    """Ambiguity dilution of precision, det(Q)^(1/(2n)) (cycles), invariant under Z-transformations."""
    d = ltdl(Q)[1]
    return float(np.exp(np.mean(np.log(d)) / 2.0))


def adop_success_rate(Q) -> float:
    """ADOP-based approximation of the ILS success rate: (2 Phi(1 / (2 ADOP)) - 1)^n."""
    n = np.shape(Q)[0]
    return float(_p1(adop(Q) ** 2) ** n)


def adop_upper_bound(Q) -> float:
    """ADOP-based upper bound of the ILS success rate: P(chi2_n <= c_n / ADOP^2), c_n = (n/2 Gamma(n/2))^(2/n) / pi."""
    n = np.shape(Q)[0]
    cn = math.exp((2.0 / n) * (math.log(n / 2.0) + gammaln(n / 2.0))) / math.pi
    return float(chi2.cdf(cn / adop(Q) ** 2, n))


def success_rate_bounds(Q, decorrelate_first=True) -> dict:
    """Easy bounds and approximations of the ILS success rate.

    Keys: ``bootstrap_exact`` (exact IB rate, lower bound of ILS), ``adop_approx``, ``adop_upper``,
    ``variance_lower`` (prod of per-ambiguity rounding rates), ``eigen_lower`` / ``eigen_upper`` (from the
    largest / smallest eigenvalue of Q). Those marked by parametrisation use Qz when ``decorrelate_first``.
    """
    Qm = np.asarray(Q, dtype=np.float64)
    dec = decorrelate(Qm)
    Qp = dec.Qz if decorrelate_first else Qm
    n = Qm.shape[0]
    lam = np.linalg.eigvalsh(Qp)
    return {
        "bootstrap_exact": bootstrap_success_rate(d=dec.d if decorrelate_first else ltdl(Qm)[1]),
        "adop_approx": adop_success_rate(Qm),
        "adop_upper": adop_upper_bound(Qm),
        "variance_lower": float(np.prod(_p1(np.diag(Qp)))),
        "eigen_lower": float(_p1(lam[-1]) ** n),
        "eigen_upper": float(_p1(lam[0]) ** n),
    }


def monte_carlo_success_rate(Q, n_samples, rng, estimator="ils"):
    """Monte Carlo success rate: the fraction of ``n_samples`` draws a_hat ~ N(0, Q) mapped back to 0.

    ``rng`` is a seeded ``numpy.random.Generator``; ``estimator`` is "ils", "bootstrap" or "rounding" (the latter
    two in the decorrelated parametrisation). Returns (rate, standard error sqrt(p (1 - p) / N)).
    """
    from .search import ils_batch

    Qm = np.asarray(Q, dtype=np.float64)
    n = Qm.shape[0]
    e = rng.standard_normal((int(n_samples), n)) @ np.linalg.cholesky(Qm).T
    if estimator == "ils":
        ok = np.all(ils_batch(e, Qm, n_cands=1).candidates[:, 0, :] == 0, axis=1)
    elif estimator in ("bootstrap", "rounding"):
        dec = decorrelate(Qm)
        z = e @ dec.Z.astype(np.float64)
        fixed = round_half_up(z) if estimator == "rounding" else bootstrap_z(z, dec.L)
        ok = np.all(fixed == 0, axis=1)
    else:
        raise AmbiguityInputError("estimator", f"{estimator!r}; expected 'ils', 'bootstrap' or 'rounding'")
    p = float(np.mean(ok))
    return p, math.sqrt(max(p * (1.0 - p), 1e-300) / len(ok))
