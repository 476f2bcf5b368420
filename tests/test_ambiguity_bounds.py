"""Pull-in region bounds of the ILS success rate (simkit.ambiguity.success) against the published LAMBDA 4.0
example, closed-form diagonal cases (where the ILS success rate is exact) and Monte Carlo ILS on random problems."""
import json

import numpy as np
import pytest
from scipy.special import erf

from simkit import ambiguity as amb
from studies.ambiguity_problems import random_problem
from simkit.ambiguity.success import ils_success_bounds, pullin_lower_bound, pullin_upper_bound

from conftest import DATA as _DATA_DIR

EXAMPLE = json.loads((_DATA_DIR / "lambda_testvectors.json").read_text())["ps_lambda4_example2"]


def _example_Q():
    L = np.array(EXAMPLE["L"])
    return L.T @ np.diag(EXAMPLE["d_vec"]) @ L


def test_lambda4_pullin_bounds():
    """LAMBDA 4.0 RUN_example_2 prints LB_Pullin 94.9 % and UB_Pullin 97.13 % (both parametrisations: the ILS
    pull-in region does not depend on the Z-transformation)."""
    Q = _example_Q()
    dec = amb.decorrelate(Q)
    for q in (Q, dec.Qz):
        assert pullin_lower_bound(q) == pytest.approx(0.949, abs=5e-4)
        assert pullin_upper_bound(q) == pytest.approx(0.9713, abs=5e-5)
        b = ils_success_bounds(q)
        assert b["adop_upper"] == pytest.approx(0.9774, abs=5e-5)  # the example's UB_ADOP
        assert b["bootstrap"] == pytest.approx(0.9708, abs=5e-5)   # its IB_exact, decorrelated
        assert b["lower"] <= b["upper"]


@pytest.mark.parametrize("sigmas", [[0.1, 0.15, 0.2, 0.25, 0.3], [0.4, 0.2], [0.05, 0.3, 0.3, 0.12, 0.2, 0.26, 0.18]])
def test_diagonal_exact(sigmas):
    """Diagonal Q: the pull-in region is the unit cube, P = prod(2 Phi(1 / (2 sigma_i)) - 1) exactly; the band
    bound with the unit vectors and the bootstrapped rate both equal it, the ellipsoid bound lies below. Without
    the extra searches (rounds=0) the longest unit vector can be missing from the 4n shortest: still a bound."""
    s = np.array(sigmas)
    exact = np.prod(erf(1.0 / (2.0 * s) / np.sqrt(2.0)))
    b = ils_success_bounds(np.diag(s**2), rounds=2)
    assert ils_success_bounds(np.diag(s**2))["pullin_upper"] >= exact
    assert b["bootstrap"] == pytest.approx(exact, rel=1e-12)
    assert b["pullin_upper"] == pytest.approx(exact, rel=1e-12)
    assert b["pullin_lower"] < exact < b["adop_upper"]


def test_bounds_bracket_monte_carlo_ils():
    """30 random problems n = 2..8 (well and badly conditioned, scaled to informative rates): every lower bound
    is below and every upper bound above the Monte Carlo ILS success rate (10,000 draws) within 4 sigma."""
    rng = np.random.default_rng(12)
    Qs, rates = [], []
    for i in range(30):
        n = int(rng.integers(2, 9))
        _, Q, _ = random_problem(rng, n, "well" if i % 2 else "bad")
        Q = Q * (0.02 / np.exp(np.mean(np.log(np.linalg.eigvalsh(Q)))) * rng.uniform(1, 6))  # ADOP ~ 0.14-0.35
        Qs.append(Q)
        p, se = amb.monte_carlo_success_rate(Q, 10_000, np.random.default_rng(100 + i))
        b = ils_success_bounds(Q)
        tol = 4 * max(se, 1.0 / 10_000)
        for key in ("bootstrap", "pullin_lower", "lower"):
            assert b[key] <= p + tol, (i, key, b[key], p)
        for key in ("pullin_upper", "adop_upper", "upper"):
            assert b[key] >= p - tol, (i, key, b[key], p)
        rates.append((p, b["lower"], b["upper"]))
    rates = np.array(rates)
    assert np.median(rates[:, 2] - rates[:, 1]) < 0.15  # informative, not vacuous
    assert 0.05 < np.median(rates[:, 0]) < 0.95


def test_stacked_equals_single_and_bad_shape():
    rng = np.random.default_rng(3)
    Qs = np.stack([random_problem(rng, 5, "well")[1] * 4 for _ in range(6)])
    stacked = ils_success_bounds(Qs)
    for k in range(6):
        one = ils_success_bounds(Qs[k])
        for key, v in one.items():
            assert stacked[key][k] == pytest.approx(v, rel=1e-12)
    assert stacked["adop_upper"] == pytest.approx([amb.adop_upper_bound(q) for q in Qs], rel=1e-10)
    with pytest.raises(amb.AmbiguityInputError, match="Q"):
        ils_success_bounds(np.ones(3))
