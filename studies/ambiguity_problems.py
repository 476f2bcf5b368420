"""Random ambiguity problems with controlled conditioning, for tests, benchmarks and experiments."""
from __future__ import annotations

import numpy as np


def random_problem(rng, n, conditioning="well", magnitude=1e4):
    """A random (a_hat (n,), Q (n, n), a_true (n,) int64) problem, cycles and cycles^2.

    ``Q = L^T diag(d) L`` with a random unit lower-triangular ``L`` and log-uniform conditional variances ``d``:
    "well": |L| ~ 0.3, d in [0.005, 0.1] (a few hours of dual-frequency data); "bad": |L| ~ min(1.5, 4.5/sqrt(n)),
    d in [1e-4, 0.5] (strongly correlated, as GNSS ambiguities in their original parametrisation; condition
    numbers ~1e4 at n = 5 up to ~1e9-1e11 at n = 20..40, the range float64 can still solve to ~1e-7). ``a_true`` is
    uniform in +-``magnitude`` and ``a_hat = a_true + e``, e ~ N(0, Q). ``rng``: a numpy Generator.
    """
    spread, (lo, hi) = {"well": (0.3, (0.005, 0.1)), "bad": (min(1.5, 4.5 / np.sqrt(n)), (1e-4, 0.5))}[conditioning]
    L = np.tril(rng.normal(0.0, spread, (n, n)), -1) + np.eye(n)
    d = np.exp(rng.uniform(np.log(lo), np.log(hi), n))
    Q = L.T @ (d[:, None] * L)
    Q = 0.5 * (Q + Q.T)
    a_true = rng.integers(-int(magnitude), int(magnitude) + 1, n)
    a_hat = a_true + np.linalg.cholesky(Q) @ rng.standard_normal(n)
    return a_hat, Q, a_true
