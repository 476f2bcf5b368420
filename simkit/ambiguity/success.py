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


def _adop_of(d):
    """ADOP (...,) cycles from conditional variances ``d`` (..., n) of any LtDL factorisation (Z-invariant)."""
    return np.exp(np.mean(np.log(d), axis=-1) / 2.0)


def _adop_upper_of(d):
    """P(chi2_n <= c_n / ADOP^2), c_n = (n/2 Gamma(n/2))^(2/n) / pi, from conditional variances ``d`` (..., n):
    the ILS pull-in region has volume 1, and no region of volume 1 is more likely than the ellipsoid."""
    n = np.shape(d)[-1]
    cn = math.exp((2.0 / n) * (math.log(n / 2.0) + gammaln(n / 2.0))) / math.pi
    return chi2.cdf(cn / _adop_of(d) ** 2, n)


def adop(Q) -> float:
    """Ambiguity dilution of precision, det(Q)^(1/(2n)) (cycles), invariant under Z-transformations."""
    return float(_adop_of(ltdl(Q)[1]))


def adop_success_rate(Q) -> float:
    """ADOP-based approximation of the ILS success rate: (2 Phi(1 / (2 ADOP)) - 1)^n."""
    n = np.shape(Q)[0]
    return float(_p1(adop(Q) ** 2) ** n)


def adop_upper_bound(Q) -> float:
    """ADOP-based upper bound of the ILS success rate: P(chi2_n <= c_n / ADOP^2), c_n = (n/2 Gamma(n/2))^(2/n) / pi."""
    return float(_adop_upper_of(ltdl(Q)[1]))


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


def _as_stack(Q):
    """(K, n, n) float64 view of one (n, n) or a stack of covariances, and whether a single one was given."""
    Qs = np.asarray(Q, dtype=np.float64)
    if Qs.ndim not in (2, 3) or Qs.shape[-1] != Qs.shape[-2]:
        raise AmbiguityInputError("Q", f"shape {Qs.shape}; expected (n, n) or (K, n, n)")
    return (Qs[None], True) if Qs.ndim == 2 else (Qs, False)


def _out(x, single):
    return float(x[0]) if single else x


def shortest_lattice_vectors(Q, n_cands=None, max_nodes=1_000_000):
    """The shortest nonzero integer vectors c in the metric of ``Q`` (||c||^2_Q = c' Q^-1 c), by an ILS search
    around 0. ``Q`` (n, n) or (K, n, n). Returns (candidates (K, m, n) int64, squared norms (K, m), finished (K,),
    decorrelated conditional variances d (K, n)), ``m = n_cands - 1`` (default ``4 n``: the zero vector dropped),
    shortest first, each c beside -c."""
    from .search import ils_batch

    Qs, _ = _as_stack(Q)
    K, n = Qs.shape[:2]
    m = 4 * n + 1 if n_cands is None else int(n_cands)
    res = ils_batch(np.zeros((K, n)), Qs, n_cands=m, max_nodes=max_nodes)
    return res.candidates[:, 1:], res.sqnorms[:, 1:], np.asarray(res.finished, bool), res.d


def _independent(C, tol=1e-6):
    """Greedy choice, per problem, of up to n linearly independent rows of C (K, m, n) in order: (K, n, n) float
    with the chosen rows first and zero rows where fewer than n were found, and (K, n) bool marking real rows."""
    K, m, n = C.shape
    U = np.zeros((K, n, n))          # orthonormal basis of the chosen rows, one per row slot
    out, real = np.zeros((K, n, n)), np.zeros((K, n), bool)
    count = np.zeros(K, np.int64)
    rows = np.arange(K)
    for j in range(m):
        c = C[:, j].astype(np.float64)
        r = c - np.einsum("ki,kil->kl", np.einsum("kij,kj->ki", U, c), U)
        norm = np.linalg.norm(r, axis=1)
        take = (norm > tol * np.linalg.norm(c, axis=1)) & (count < n)
        k = rows[take]
        U[k, count[take]] = r[take] / norm[take, None]
        out[k, count[take]] = c[take]
        real[k, count[take]] = True
        count += take
    return out, real


def _lower_from(s2_min, n, finished):
    return np.where(finished, chi2.cdf(s2_min / 4.0, n), np.nan)


def _upper_from(Qs, C, max_nodes, rounds):
    """Band upper bound (K,) from the candidate lists C (K, m, n); problems with fewer than n independent
    candidates search again with 4x as many (up to ``rounds`` times) before the missing bands are left out."""
    K, n = Qs.shape[:2]
    m = C.shape[1] + 1
    C, real = _independent(C)
    short = np.flatnonzero(~real.all(axis=1))
    for _ in range(rounds):
        if short.size == 0:
            break
        m *= 4
        Cs, _, _, _ = shortest_lattice_vectors(Qs[short], m, max_nodes)
        C[short], real[short] = _independent(Cs)
        short = short[~real[short].all(axis=1)]
    W = np.linalg.solve(Qs, np.swapaxes(C, 1, 2))                        # Q^-1 c_i as columns (K, n, n)
    G = C @ W                                                            # c_i' Q^-1 c_j
    norm = np.sqrt(np.where(real, np.diagonal(G, axis1=1, axis2=2), 1.0))
    Qv = G / (norm[:, :, None] * norm[:, None, :])
    Qv = np.where(real[:, :, None] & real[:, None, :], Qv, np.eye(n))  # missing rows: unconstrained, independent
    s = np.diagonal(np.linalg.cholesky(Qv), axis1=1, axis2=2)           # conditional standard deviations
    return np.prod(np.where(real, erf(norm / (2.0 * s) / math.sqrt(2.0)), 1.0), axis=1)


def pullin_lower_bound(Q, max_nodes=1_000_000):
    """Lower bound of the ILS success rate from the largest ellipsoid inside the pull-in region (Teunissen 1998):
    P(chi2_n <= min_{c != 0} ||c||^2_Q / 4). ``Q`` (n, n) -> float or (K, n, n) -> (K,); NaN where the search for
    the shortest vector hit ``max_nodes`` (the bound would not be proven)."""
    Qs, single = _as_stack(Q)
    _, s2, done, _ = shortest_lattice_vectors(Qs, n_cands=2, max_nodes=max_nodes)
    return _out(_lower_from(s2[:, 0], Qs.shape[1], done), single)


def pullin_upper_bound(Q, n_cands=None, max_nodes=1_000_000, rounds=0):
    """Upper bound of the ILS success rate from the bands around the pull-in region (Teunissen 1998; Verhagen 2003).

    The pull-in region lies inside every band |c' Q^-1 x| <= ||c||^2_Q / 2 of a nonzero integer c. For p <= n
    independent c_i (the shortest ones, greedily), v_i = c_i' Q^-1 x / ||c_i||_Q has unit variance, and
    P(all |v_i| <= ||c_i||_Q / 2) <= prod_i (2 Phi(||c_i||_Q / (2 sigma_{v_i | v_1..v_i-1})) - 1): a conditioned
    centred Gaussian is at least as likely in a symmetric interval as a shifted one. Valid for any choice of c_i
    (a capped search only loosens it). ``Q`` (n, n) -> float or (K, n, n) -> (K,). ``rounds``: how many times a
    problem whose ``n_cands`` shortest vectors span fewer than n dimensions searches again with 4x as many (the
    missing bands are left out otherwise: still a bound, looser by their factors, which are near 1 when, as for
    code-based GNSS floats, the missing directions are the long ones).
    """
    Qs, single = _as_stack(Q)
    C = shortest_lattice_vectors(Qs, n_cands, max_nodes)[0]
    return _out(_upper_from(Qs, C, max_nodes, rounds), single)


def ils_success_bounds(Q, max_nodes=1_000_000, rounds=0) -> dict:
    """Lower and upper bounds of the ILS success rate of each covariance, arrays in and out (one search each).

    ``Q`` (n, n) -> floats or (K, n, n) -> (K,) arrays. Keys: ``bootstrap`` (exact IB rate after decorrelation,
    a lower bound), ``pullin_lower`` (ellipsoid inside the pull-in region), ``pullin_upper`` (bands around it),
    ``adop_upper`` (volume: P(chi2_n <= c_n / ADOP^2), the pull-in region has volume 1), ``lower`` = max of the
    lower bounds, ``upper`` = min of the upper bounds. ``rounds``: see :func:`pullin_upper_bound`.
    """
    Qs, single = _as_stack(Q)
    C, s2, done, d = shortest_lattice_vectors(Qs, max_nodes=max_nodes)
    out = {"bootstrap": np.atleast_1d(bootstrap_success_rate(d=d)),
           "pullin_lower": _lower_from(s2[:, 0], Qs.shape[1], done),
           "pullin_upper": _upper_from(Qs, C, max_nodes, rounds), "adop_upper": _adop_upper_of(d)}
    out["lower"] = np.fmax(out["bootstrap"], out["pullin_lower"])
    out["upper"] = np.fmin(out["pullin_upper"], out["adop_upper"])
    return {k: _out(v, single) for k, v in out.items()}


def simulated_solutions(Qs, n_samples, rng, n_cands, chunk=50_000):
    """Monte Carlo ILS of a stack ``Qs`` (K, n, n) (cycles^2): ``n_samples`` draws a_hat ~ N(0, Q_k) per problem,
    solved in batches of about ``chunk``. Yields (slice of k, :class:`~.search.ILSBatchResult` of its
    len(slice) * n_samples problems, problem-major); the true integers are 0. Draws in epoch order
    (deterministic for a seeded ``rng``)."""
    from .search import ils_batch

    K, n = Qs.shape[:2]
    L = np.linalg.cholesky(Qs)
    step = max(1, chunk // n_samples)
    for s in range(0, K, step):
        k = slice(s, min(s + step, K))
        e = np.einsum("kij,ksj->ksi", L[k], rng.standard_normal((L[k].shape[0], n_samples, n)))
        yield k, ils_batch(e.reshape(-1, n), np.repeat(Qs[k], n_samples, axis=0), n_cands=n_cands)


def monte_carlo_success_rates(Q, n_samples, rng, chunk=50_000):
    """Monte Carlo ILS success rate of each covariance of a stack ``Q`` (K, n, n) (cycles^2): ``n_samples`` draws
    a_hat ~ N(0, Q_k) each, solved in batches of about ``chunk`` problems. Returns (rates (K,), standard errors
    (K,)); ``rng`` a seeded ``numpy.random.Generator`` (draws in epoch order: deterministic)."""
    Qs, _ = _as_stack(Q)
    N = int(n_samples)
    ok = np.zeros(Qs.shape[0])
    for k, res in simulated_solutions(Qs, N, rng, 1, chunk):
        ok[k] = np.all(res.candidates[:, 0, :] == 0, axis=1).reshape(-1, N).mean(axis=1)
    return ok, np.sqrt(np.maximum(ok * (1.0 - ok), 1e-300) / N)
