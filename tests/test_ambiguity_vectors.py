"""The published LAMBDA test vectors (tests/data/lambda_testvectors.json, provenance in tests/data/SOURCES.md)
reproduced by simkit.ambiguity."""
import json

import numpy as np
import pytest

from simkit import ambiguity as amb

from conftest import DATA as _DATA_DIR

VECTORS = _DATA_DIR / "lambda_testvectors.json"
DATA = json.loads(VECTORS.read_text())
CASES = sorted(DATA["cases"])
# sqnorm tolerance: 1e-9 relative; the 6- and 12-dimensional covariances (entries ~1e4 cycles^2) are so badly
# conditioned that float64 arithmetic, ours and the file's alike, lands ~1e-9..6e-9 from the exact (50-digit)
# value of the squared norm, so they are held to 1e-8; the 18-dimensional one to 1e-6 as the file's note says.
SQ_RTOL = {"sixdim": 1e-8, "large": 1e-8, "amb18": 1e-6}


def _case(name):
    c = DATA["cases"][name]
    return np.array(c["a_float"]), np.array(c["Q"]), c["expected"]


@pytest.mark.parametrize("name", CASES)
def test_ils_candidates_and_sqnorms(name):
    a, Q, e = _case(name)
    k = len(e["best_k_candidates"])
    res = amb.ils(a, Q, n_cands=k)
    assert res.status == "finished"
    np.testing.assert_array_equal(res.candidates[0], e["ils_best"])
    np.testing.assert_array_equal(res.candidates[1], e["ils_second"])
    np.testing.assert_array_equal(res.candidates, e["best_k_candidates"])
    rtol = SQ_RTOL.get(name, 1e-9)
    np.testing.assert_allclose(res.sqnorms[:2], e["sqnorm"], rtol=rtol)
    np.testing.assert_allclose(res.sqnorms, e["best_k_candidates_sqnorm"], rtol=rtol)
    assert res.sqnorms[0] / res.sqnorms[1] == pytest.approx(e["ratio_sq1_over_sq2"], rel=2 * rtol)


@pytest.mark.parametrize("name", CASES)
def test_ratio_is_defined_for_every_n_cands(name):
    a, Q, e = _case(name)
    two = amb.ils(a, Q, n_cands=2)
    assert two.ratio == pytest.approx(1.0 / e["ratio_sq1_over_sq2"], rel=2 * SQ_RTOL.get(name, 1e-9))
    one = amb.ils(a, Q, n_cands=1)  # no second candidate: NaN (documented), never an IndexError
    np.testing.assert_array_equal(one.candidates[0], e["ils_best"])
    assert np.isnan(one.ratio)
    assert not one.ratio >= amb.DEFAULT_RATIO_THRESHOLD  # NaN accepts no fix


@pytest.mark.parametrize("name", CASES)
def test_decorrelation_and_bootstrap_success_rate(name):
    a, Q, e = _case(name)
    dec = amb.decorrelate(Q)
    np.testing.assert_allclose(dec.d, e["d_decorrelated"], rtol=1e-7)
    assert abs(round(np.linalg.det(dec.Z.astype(float)))) == 1
    np.testing.assert_allclose(dec.Z.T @ Q @ dec.Z, dec.Qz, rtol=1e-6, atol=1e-9 * np.abs(Q).max())
    np.testing.assert_array_equal(dec.Zti.T @ dec.Z, np.eye(len(a), dtype=np.int64))
    assert amb.bootstrap_success_rate(Q) == pytest.approx(e["Ps_bootstrap_after_decorrelation"], rel=1e-8)


def test_small_example_matches_lgr12():
    a, Q, e = _case("small")
    pub = DATA["cases"]["small"]["published"]
    dec = amb.decorrelate(Q, a)
    np.testing.assert_array_equal(dec.Z.T, e["ZT_our_ordering"])
    np.testing.assert_allclose(dec.Qz, e["Qz_our_ordering"], atol=1e-9)
    np.testing.assert_allclose(dec.z_hat, e["z_hat_our_ordering"], atol=1e-12)
    # LGR-12's own ordering is a permutation of ours; the set of rows and the values agree
    assert sorted(map(tuple, dec.Z.T.tolist())) == sorted(map(tuple, pub["Zstar_rows"]))
    assert sorted(np.round(np.diag(dec.Qz), 3)) == sorted(np.diag(pub["Qz"]))
    res = amb.ils(a, Q, n_cands=2)
    np.testing.assert_array_equal(res.candidates[0], pub["a_check"])
    assert res.sqnorms[0] == pytest.approx(pub["sqnorm"], abs=5e-4)


@pytest.mark.parametrize("name", CASES)
def test_rounding(name):
    a, Q, e = _case(name)
    np.testing.assert_array_equal(amb.rounding(a), e["IR_no_decorrelation"])
    np.testing.assert_array_equal(amb.rounding(a, Q), e["IR_after_decorrelation"])


def _bootstrap_from_covariance(z_hat, Qz):
    """Bootstrapping written from the conditional means of Qz directly (no LtDL), as an independent referee."""
    n = z_hat.size
    z = np.zeros(n)
    for k in range(n - 1, -1, -1):
        j = slice(k + 1, n)
        m = z_hat[k] + (Qz[k, j] @ np.linalg.solve(Qz[j, j], z[j] - z_hat[j]) if k < n - 1 else 0.0)
        z[k] = np.floor(m + 0.5)
    return z


@pytest.mark.parametrize("name", CASES)
def test_bootstrapping(name):
    # The file's IB_after_decorrelation equals ours only for "geofree": for small/sixdim/large it is reproduced by
    # conditioning with the wrong sign (see docs/ambiguity.md, errata). We test against the conditional means.
    a, Q, e = _case(name)
    shift = np.floor(a + 0.5)
    dec = amb.decorrelate(Q, a - shift)
    ref = dec.Zti @ _bootstrap_from_covariance(dec.z_hat, dec.Qz).astype(np.int64) + shift.astype(np.int64)
    np.testing.assert_array_equal(amb.bootstrapping(a, Q), ref)
    if name == "geofree":
        np.testing.assert_array_equal(amb.bootstrapping(a, Q), e["IB_after_decorrelation"])


@pytest.mark.parametrize("name", CASES)
def test_partial_fixing(name):
    a, Q, e = _case(name)
    for p0, want in e["PAR"].items():
        par = amb.partial_fix(a, Q, p0=float(p0))
        assert par.n_fixed == want["nfixed"]
        if want["Ps_PAR"] is None:
            assert par.success_rate is None
        else:
            assert par.success_rate == pytest.approx(want["Ps_PAR"], rel=1e-8)
            assert par.success_rate >= float(p0)
            # the fixed combinations are integer combinations of a and agree with the full ILS solution when
            # everything is fixed
            if par.n_fixed == len(a):
                np.testing.assert_array_equal(par.z_fixed, par.Z_fixed.T @ amb.ils(a, Q).candidates[0])


def test_lambda4_success_rate_example():
    ex = DATA["ps_lambda4_example2"]
    L = np.array(ex["L"])
    Q = L.T @ np.diag(ex["d_vec"]) @ L
    want = {k: np.array(v) / 100 for k, v in ex["SR_percent"].items()}
    dec = amb.decorrelate(Q)
    np.testing.assert_allclose(dec.d, ex["decorrelated_d_ours"], atol=1e-8)
    assert dec.L[1, 0] == pytest.approx(ex["decorrelated_L21_ours"], abs=1e-8)
    for col, decor in enumerate((False, True)):
        b = amb.success_rate_bounds(Q, decorrelate_first=decor)
        for key, name in (("IB_exact", "bootstrap_exact"), ("ADOP_approx", "adop_approx"),
                          ("LB_Variance", "variance_lower"), ("UB_ADOP", "adop_upper"),
                          ("LB_Eigenvalue", "eigen_lower"), ("UB_Eigenvalue", "eigen_upper")):
            assert b[name] == pytest.approx(want[key][col], abs=5e-5), (key, decor)


def test_fixed_failure_rate_ratio_test():
    """FF-ratio test. The file's mu values come from LAMBDA 3.0's generic lookup table (ratiotab.mat, not
    available); ours are calibrated by Monte Carlo on each model, so mu differs, but the limiting cases and the
    clear-cut decisions agree."""
    for name in CASES:
        a, Q, e = _case(name)
        res = amb.ils(a, Q)
        for pf, want in e["FFRT_LAMBDA3"].items():
            mu = amb.ffrt_threshold(Q, failure_rate=float(pf), n_samples=20_000, seed=1)
            if want["mu"] == 1.0:  # ILS failure rate already below the tolerance
                assert mu == 1.0
            decision = amb.ffrt(res, mu)
            if name == "large" and pf == "0.001":
                _large_borderline(res, Q, mu, want["mu"])
                continue
            assert decision == want["accepted"], (name, pf, mu)


def _large_borderline(res, Q, mu, table_mu):
    """'large' at Pf = 0.001: its ratio (0.475) lies between the generic table's mu (0.430, reject) and ours
    (~0.60, accept). The FF test's own definition decides: by Monte Carlo on this model, accepting every
    solution with ratio <= 0.475 fails with probability ~3e-4 < 1e-3, so acceptance is within the tolerance,
    and the table's mu (~2e-4) is conservative for this model (LAMBDA 3.0's table is fitted over many models)."""
    rng = np.random.default_rng(11)
    e = rng.standard_normal((30_000, Q.shape[0])) @ np.linalg.cholesky(Q).T
    r = amb.ils_batch(e, Q, n_cands=2)
    wrong = np.any(r.candidates[:, 0, :] != 0, axis=1)
    ratios = r.sqnorms[:, 0] / r.sqnorms[:, 1]
    case_ratio = res.sqnorms[0] / res.sqnorms[1]
    assert table_mu < case_ratio < mu and amb.ffrt(res, mu)
    assert np.mean(wrong & (ratios <= case_ratio)) < 1e-3
    assert np.mean(wrong & (ratios <= table_mu)) < np.mean(wrong & (ratios <= mu))
