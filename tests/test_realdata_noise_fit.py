"""The per-bin statistics of simkit/realdata/noise_fit.py against closed forms and Monte Carlo: the lag-one
autocorrelation and n_eff of AR(1) series, the standard error of a sigma, equal-count bins, the smooth
code-factor correction, and the C/N0 bias / scatter split."""
import numpy as np
import pytest

from simkit.realdata import noise_fit, twin


def _ar1(m, s, rho, rng):
    """(m, s) unit-variance AR(1) columns with lag-one autocorrelation ``rho``."""
    x = np.empty((m, s))
    x[0] = rng.standard_normal(s)
    w = rng.standard_normal((m, s)) * np.sqrt(1 - rho ** 2)
    for k in range(1, m):
        x[k] = rho * x[k - 1] + w[k]
    return x


@pytest.mark.parametrize("rho", [0.0, 0.5, 0.8])
def test_lag_one_and_n_eff_of_an_ar1_series(rho):
    rng = np.random.default_rng(3)
    x = _ar1(400, 50, rho, rng)
    assert noise_fit.lag_one(x) == pytest.approx(rho, abs=0.02)
    assert noise_fit.n_effective(1000, rho) == pytest.approx(1000 * (1 - rho) / (1 + rho))
    assert noise_fit.n_effective(1000, rho, "variance") == pytest.approx(1000 * (1 - rho ** 2) / (1 + rho ** 2))
    assert noise_fit.n_effective(10, -0.3) == 10 and noise_fit.n_effective(10, None) == 10


def test_the_standard_error_of_a_bin_sigma_matches_its_monte_carlo_scatter():
    """Over many draws of a bin of 20 satellites x 30 epochs of AR(1) noise (rho 0.6), the relative scatter of
    the bin's sigma is what rel_se = 1 / sqrt(2 n_eff) says (within 20 %), n_eff = n (1 - rho^2) / (1 + rho^2):
    1 / sqrt(2 n) would be too small, the n_eff of a mean too large."""
    rng = np.random.default_rng(7)
    rho, sigmas, se = 0.6, [], []
    el = np.full((30, 20), 30.0)
    for _ in range(300):
        st = noise_fit.bin_sigma(2.0 * _ar1(30, 20, rho, rng), el, 20.0, 40.0)
        sigmas.append(st["sigma"])
        se.append(st["rel_se"])
    scatter = np.std(sigmas) / np.mean(sigmas)
    assert np.mean(sigmas) == pytest.approx(2.0, rel=0.05)
    assert np.mean(se) == pytest.approx(scatter, rel=0.2)
    assert scatter > 1.25 / np.sqrt(2 * 600) and scatter < 0.8 / np.sqrt(2 * 600 * 0.4 / 1.6)


def test_equal_count_edges_keep_enough_effective_values_per_bin():
    rng = np.random.default_rng(1)
    el = rng.uniform(5, 85, (200, 10))
    v = rng.standard_normal((200, 10))
    edges = noise_fit.equal_count_edges(v, el, 5.0, n_eff_min=380, max_bins=6)
    assert len(edges) == 6 and edges[0] == 5.0 and edges[-1] == 90.0     # 2000 white values: 5 bins of 400
    counts = np.histogram(el, edges)[0]
    assert counts.min() >= 380
    assert len(noise_fit.equal_count_edges(v, el, 5.0, n_eff_min=50, max_bins=6)) == 7   # capped
    assert noise_fit.equal_count_edges(np.full((3, 3), np.nan), el[:3, :3], 5.0) == [5.0, 90.0]


def test_code_comparison_pools_realisations_and_flags_a_real_mismatch():
    """A twin 1.5x noisier than the real series in every bin: each bin's ratio is 1.5 within its standard
    error, and the summary counts it as beyond two standard errors; with the same noise no bin is."""
    rng = np.random.default_rng(11)
    el = np.radians(np.tile(np.linspace(5, 85, 40), (300, 1)))
    real = {"L1C": 0.5 * _ar1(300, 40, 0.3, rng)}
    noisy = [{"L1C": 0.75 * _ar1(300, 40, 0.3, rng)} for _ in range(3)]
    out = noise_fit.code_comparison(real, noisy, el, 5.0, n_eff_min=500)
    rows = out["signals"]["L1C"]["bins"]
    assert out["twin_realisations"] == 3 and len(rows) == 6
    for b in rows:
        assert abs(b["ratio"] - 1.5) < 3 * 1.5 * b["ratio_rel_se"]
        assert b["twin_n_eff"] > 2.5 * b["real_n_eff"]      # three realisations pooled
    assert out["summary"]["beyond_two_se"] == 6 and out["summary"]["within"] == 0
    same = [{"L1C": 0.5 * _ar1(300, 40, 0.3, rng)} for _ in range(3)]
    s = noise_fit.code_comparison(real, same, el, 5.0, n_eff_min=500)["summary"]
    assert s["within"] == 6 and s["beyond_two_se"] <= 1 and s["chi2_per_bin"] < 3
    assert 5.5 < s["expected_within_if_equal"] <= 6          # standard errors of a few percent: all of them


def test_smooth_correction_removes_a_log_linear_trend_in_two_parameters():
    """Ratios exp(0.2 + 0.3 x) in six bins (x = (el - 45) / 45) with small errors: the corrected factor is the
    current one divided by that trend at every node; one bin gives a level only (the ridge holds the slope)."""
    edges = np.linspace(5, 85, 7)
    centres = 0.5 * (edges[:-1] + edges[1:])
    bins = [{"bin_deg": [a, b], "ratio": float(np.exp(0.2 + 0.3 * (c - 45) / 45)), "ratio_rel_se": 0.01}
            for a, b, c in zip(edges[:-1], edges[1:], centres)]
    out = noise_fit.smooth_correction({"L1C": {"bins": bins}}, {"L1C": 2.0})
    nodes, f = np.array(out["L1C"][0]), np.array(out["L1C"][1])
    assert f == pytest.approx(2.0 / np.exp(0.2 + 0.3 * (nodes - 45) / 45), rel=0.01)
    one = noise_fit.smooth_correction({"L1C": {"bins": bins[2:3]}}, {"L1C": ((0.0, 90.0), (1.0, 3.0))})
    f1 = np.array(one["L1C"][1])
    assert f1 / np.interp(one["L1C"][0], (0.0, 90.0), (1.0, 3.0)) == pytest.approx(
        np.full(f1.size, 1 / bins[2]["ratio"]), rel=0.05)


def test_cn0_comparison_splits_the_difference_into_bias_and_scatter():
    rng = np.random.default_rng(5)
    el = np.radians(np.tile(np.linspace(5, 85, 30), (100, 1)))
    real = 30 + 15 * np.sin(el) + rng.standard_normal(el.shape)
    offsets = np.where(np.degrees(el) < 45, 2.0, 0.0)      # a bias of 2 dB-Hz in the lower half of the sky
    twins = [30 + 15 * np.sin(el) + offsets + rng.standard_normal(el.shape) for _ in range(2)]
    out = noise_fit.cn0_comparison({"L1C": real}, [{"L1C": t} for t in twins], el, np.arange(0.0, 91.0, 10.0))
    c = out["L1C"]
    d = np.array([b["difference"] for b in c["bins"] if b["difference"] is not None])
    assert len(d) == 9 and c["bias_dbhz"] == pytest.approx(np.mean(d)) and c["scatter_dbhz"] > 0.8
    assert c["rms_dbhz"] ** 2 == pytest.approx(c["bias_dbhz"] ** 2 + c["scatter_dbhz"] ** 2)
    assert d[:4] == pytest.approx(2.0, abs=0.3) and d[5:] == pytest.approx(0.0, abs=0.3)


def test_cn0_spread_and_the_real_file_against_itself_in_closed_form():
    rng = np.random.default_rng(6)
    el = np.radians(np.tile(np.linspace(5, 85, 30), (400, 1)))
    level = 30 + 15 * np.sin(el)
    real = level + 5.0 * rng.standard_normal(el.shape)             # a street: 5 dB of spread about the level
    twin = level + 2.0 * rng.standard_normal(el.shape)             # a twin with too little of it
    c = noise_fit.cn0_comparison({"L1C": real}, [{"L1C": twin}], el, np.arange(0.0, 91.0, 10.0))["L1C"]
    # the spread within a bin is the noise plus the level's own variation over the bin (same in both files)
    for b in c["bins"]:
        in_bin = (np.degrees(el[0]) >= b["bin_deg"][0]) & (np.degrees(el[0]) < b["bin_deg"][1])
        lv = np.var(level[0, in_bin])
        assert b["real_sd_db"] == pytest.approx(np.sqrt(25.0 + lv), rel=0.05)
        assert b["twin_sd_db"] == pytest.approx(np.sqrt(4.0 + lv), rel=0.05)
    assert 2.0 < c["spread_rms_db"] < 3.5
    # the real file against itself: the same epochs give 0; the other epochs 2 dB higher give a bias of -2
    same = noise_fit.cn0_drift([dict(b) for b in c["bins"]], real, el)
    assert same["rms_dbhz"] == pytest.approx(0.0, abs=1e-9) and same["bins"] == 9
    up = noise_fit.cn0_drift([dict(b) for b in c["bins"]], real + 2.0, el)
    assert up["bias_dbhz"] == pytest.approx(-2.0) and up["scatter_dbhz"] == pytest.approx(0.0, abs=1e-9)
    assert up["chi2_per_bin"] > 0


@pytest.mark.parametrize("m", [19, 60, 1375])
def test_splits_fit_and_check_disjoint_blocks_long_enough_for_an_arc(m):
    t = np.arange(m) * 1.0
    half = twin.split_rows(t, "half")
    assert half[: m // 2].all() and not half[-(m // 2):].any()
    inter = twin.split_rows(t, "interleaved")
    change = np.flatnonzero(np.diff(inter.astype(int)) != 0) + 1
    blocks = np.split(inter, change)
    assert 3 <= len(blocks) <= twin.MAX_BLOCKS and min(len(b) for b in blocks) >= 6
    assert inter[0] and (~inter).any()
    with pytest.raises(Exception, match="interleaved"):
        twin.split_rows(t, "random")


def test_the_satellite_jackknife_sees_the_spread_between_satellites():
    """Satellites each with their own multipath sigma (0.5x to 2x): the bin's sigma scatters over draws of
    the satellites far more than 1 / sqrt(2 n_eff) says; the jackknife over satellites follows the Monte Carlo
    scatter (within 30 %). With one sigma for all it agrees with the n_eff figure."""
    rng = np.random.default_rng(2)
    el = np.full((20, 8), 30.0)
    for spread, lo_hi in ((True, (0.7, 1.3)), (False, (0.75, 1.25))):
        sig, jk, ne = [], [], []
        for _ in range(400):
            scale = np.exp(rng.uniform(np.log(0.5), np.log(2.0), 8)) if spread else np.ones(8)
            st = noise_fit.bin_sigma(scale * rng.standard_normal((20, 8)), el, 0.0, 90.0)
            sig.append(st["sigma"]), jk.append(st["rel_se_satellites"]), ne.append(st["rel_se"])
        scatter = np.std(sig) / np.mean(sig)
        assert lo_hi[0] < np.mean(jk) / scatter < lo_hi[1]
        if spread:
            assert scatter > 2.5 * np.mean(ne)
        else:
            assert np.mean(ne) == pytest.approx(scatter, rel=0.2)


def test_a_bin_of_one_satellite_carries_the_spread_between_satellites():
    """Satellites with their own C/N0 offsets (sd 3 dB): the pooled spread between satellites is recovered, and a
    bin holding one satellite gets a standard error of about that spread, however many epochs it has."""
    rng = np.random.default_rng(4)
    el = np.tile(np.r_[np.full(40, 20.0), 85.0], (200, 1))          # 40 satellites at 20 deg, one at 85 deg
    cn0 = 40 + rng.normal(0, 3, 41)[None, :] + 0.2 * rng.standard_normal((200, 41))
    edges = np.arange(0.0, 91.0, 10.0)
    assert noise_fit.satellite_spread(cn0, el, edges) == pytest.approx(3.0, rel=0.3)
    out = noise_fit.cn0_comparison({"L1C": cn0}, [{"L1C": np.full(cn0.shape, 40.0)}], np.radians(el), edges)
    one = out["L1C"]["bins"][8]
    assert one["real_satellites"] == 1 and one["real_se"] == pytest.approx(3.0, rel=0.3)
    assert out["L1C"]["bins"][2]["real_se"] < 1.0          # 40 satellites: about 3 / sqrt(40)
