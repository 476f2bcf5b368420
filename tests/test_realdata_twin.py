"""The twin's statistics against closed forms on synthetic series, and ``simkit twin`` on the real KMS3 file."""
from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest

from realdata_helpers import CN00_NAV, CN00_OBS, KMS3_NAV, KMS3_OBS
from simkit.cli import main
from simkit.gnss import signals as sigmod
from simkit.io import open_dataset, read_gnss
from simkit.realdata import fidelity, twin

L1, L2 = sigmod.get("L1C"), sigmod.get("L2W")


def _dual(m=400, s=3, sigma_code=0.3, sigma_phase=0.002, seed=0, dt=1.0):
    """Code and carrier of L1C and L2W over a smooth range and ionosphere with white noise of known sigma."""
    rng = np.random.default_rng(seed)
    t = np.arange(m) * dt
    rho = 2.2e7 + 500.0 * t[:, None] + 0.01 * t[:, None] ** 2 + 1e5 * np.arange(s)
    iono1 = 3.0 + 1e-3 * t[:, None] + np.zeros((1, s))
    obs = {k: {} for k in twin.KINDS}
    for g in (L1, L2):
        i = iono1 * (L1.freq_hz / g.freq_hz) ** 2
        obs["code"][g.name] = rho + i + sigma_code * rng.standard_normal((m, s))
        phase_m = rho - i + sigma_phase * rng.standard_normal((m, s))
        obs["carrier"][g.name] = phase_m / g.wavelength_m + rng.integers(-1000, 1000, s)
        obs["doppler"][g.name] = -(500.0 + 0.02 * t[:, None] + np.zeros((1, s))) / g.wavelength_m \
            + 0.05 * rng.standard_normal((m, s))
        obs["cn0"][g.name] = np.full((m, s), 45.0)
        obs["lli"][g.name] = np.zeros((m, s), np.uint8)
    return t, obs


def test_multipath_combination_cancels_range_ionosphere_and_ambiguity():
    t, obs = _dual()
    mp = fidelity.multipath(obs, ["L1C", "L2W"], [L1.freq_hz, L2.freq_hz], t)
    a = (L1.freq_hz / L2.freq_hz) ** 2
    # MP1 = P1 - (1 + 2/(a-1)) L1 + 2/(a-1) L2: the code noise plus carrier noise amplified by the coefficients
    expected = np.hypot(0.3, 0.002 * np.hypot(1 + 2 / (a - 1), 2 / (a - 1)))
    assert np.nanstd(mp["L1C"]) == pytest.approx(expected, rel=0.05)
    assert abs(np.nanmean(mp["L1C"])) < 1e-9 + 0.3 / np.sqrt(400)


def test_glonass_multipath_needs_each_satellites_own_frequency():
    """G1C/G2C of satellites on channels -7, 0 and +6: with each satellite's wavelengths (per-satellite
    frequencies, (S, G)) the combination is the code noise; with the nominal channel-0 frequencies it is not."""
    g1, g2 = sigmod.get("G1C"), sigmod.get("G2C")
    k = np.array([-7.0, 0.0, 6.0])
    f1, f2 = g1.frequency_for(k), g2.frequency_for(k)
    rng = np.random.default_rng(5)
    m, s = 400, 3
    t = np.arange(m) * 1.0
    rho = 2.2e7 + 500.0 * t[:, None] + 1e5 * np.arange(s)
    iono1 = 3.0 + 1e-3 * t[:, None] + np.zeros((1, s))
    obs = {kind: {} for kind in twin.KINDS}
    for g, f in ((g1, f1), (g2, f2)):
        i = iono1 * (f1 / f) ** 2
        obs["code"][g.name] = rho + i + 0.3 * rng.standard_normal((m, s))
        obs["carrier"][g.name] = (rho - i + 0.002 * rng.standard_normal((m, s))) * f / 299792458.0
        obs["lli"][g.name] = np.zeros((m, s), np.uint8)
    per_sat = fidelity.multipath(obs, ["G1C", "G2C"], np.stack([f1, f2], axis=1), t)
    nominal = fidelity.multipath(obs, ["G1C", "G2C"], [g1.freq_hz, g2.freq_hz], t)
    assert np.nanstd(per_sat["G1C"]) == pytest.approx(0.3, rel=0.08)
    assert np.nanstd(nominal["G1C"][:, 0]) > 3.0          # channel -7 read as channel 0: metres of drift


def test_an_lli_flag_starts_a_new_arc():
    t, obs = _dual()
    obs["carrier"]["L1C"][200:, 0] += 17.0                 # a slip of 17 cycles, flagged
    obs["lli"]["L1C"][200, 0] = 1
    mp = fidelity.multipath(obs, ["L1C", "L2W"], [L1.freq_hz, L2.freq_hz], t)
    assert np.nanstd(mp["L1C"][:, 0]) < 0.35
    assert fidelity.slips_per_hour(obs, ["L1C"], t)["L1C"] == pytest.approx(1 / (3 * 400 / 3600.0))


def test_carrier_noise_of_white_phase_from_third_differences():
    t, obs = _dual(sigma_phase=0.003)
    cn = fidelity.carrier_noise(obs, ["L1C", "L2W"], [L1.freq_hz, L2.freq_hz], t)
    assert fidelity.robust_std(cn["L1C+L2W"]) == pytest.approx(0.003 * np.sqrt(2), rel=0.08)


def test_doppler_residual_is_the_doppler_noise():
    t, obs = _dual()
    res = fidelity.doppler_residual(obs, ["L1C"], t)["L1C"]
    phase_rate_noise = 0.002 / L1.wavelength_m / np.sqrt(2)   # (e_k+1 - e_k-1) / 2 dt
    assert fidelity.robust_std(res) == pytest.approx(np.hypot(0.05, phase_rate_noise), rel=0.08)


def test_pairs_take_the_most_distant_frequency():
    names = ["L1C", "L2W", "L5Q", "B1I", "B3I", "B1C", "B2a"]
    sig = [sigmod.get(n) for n in names]
    p = fidelity.pairs(names, [g.system for g in sig], [g.freq_hz for g in sig])
    assert p["L1C"] == "L5Q" and p["B1C"] == "B2a" and p["B1I"] == "B2a" and p["B3I"] == "B1C"


def test_cn0_fit_recovers_the_simulator_model():
    rng = np.random.default_rng(3)
    m, s = 50, 8
    el = np.radians(rng.uniform(5, 85, (m, s)))
    real = {"t": np.arange(m) * 30.0, "signals": ["L1C"], "freq": [L1.freq_hz], "sat_freq": [L1.freq_hz],
            "obs": {k: {} for k in twin.KINDS}, "sat_id": [f"G{k + 1:02d}" for k in range(s)]}
    cn0 = 42.0 + L1.cn0_offset_db - 14.0 * ((np.pi / 2 - el) / (np.pi / 2)) ** 2 + 0.3 * rng.standard_normal((m, s))
    t, obs = _dual(m=m, s=s)
    real["obs"] = {k: {"L1C": obs[k]["L1C"]} for k in twin.KINDS}
    real["obs"]["cn0"]["L1C"] = cn0
    # satellites placed so that the geometry gives exactly these elevations: straight up along the local vertical
    ref = np.array([6378137.0, 0.0, 0.0])
    east = np.array([0.0, 1.0, 0.0])
    up = np.array([1.0, 0.0, 0.0])
    dist = 2.0e7
    real["sat_pos"] = ref + dist * (np.cos(el)[..., None] * east + np.sin(el)[..., None] * up)
    p = twin.fit_parameters(real, ref)
    assert p["cn0_zenith_dbhz"] == pytest.approx(42.0, abs=0.2) and p["rolloff_db"] == pytest.approx(14.0, abs=0.4)


def _two_signal_cn0(l2_rolloff_db, seed=4, satellite_db=None):
    """A synthetic static file whose L1C C/N0 follows the quadratic model and whose L2W falls by a further
    ``l2_rolloff_db`` (theta / 90 deg)^2 below it (plus a constant 3 dB), 0.3 dB-Hz white noise on both; each
    satellite k's L2W moved by ``satellite_db[k]`` when given."""
    rng = np.random.default_rng(seed)
    m, s = 120, 10
    el = np.radians(rng.uniform(5, 85, (m, s)))
    x = ((np.pi / 2 - el) / (np.pi / 2)) ** 2
    l2 = sigmod.get("L2W")
    t, obs = _dual(m=m, s=s)
    real = {"t": t, "signals": ["L1C", "L2W"], "freq": [L1.freq_hz, l2.freq_hz],
            "sat_freq": np.tile([L1.freq_hz, l2.freq_hz], (s, 1)), "obs": {k: dict(obs[k]) for k in twin.KINDS},
            "sat_id": [f"G{k + 1:02d}" for k in range(s)]}
    real["obs"]["cn0"] = {"L1C": 48.0 + L1.cn0_offset_db - 14.0 * x + 0.3 * rng.standard_normal((m, s)),
                          "L2W": 48.0 + l2.cn0_offset_db - 3.0 - (14.0 + l2_rolloff_db) * x
                          + 0.3 * rng.standard_normal((m, s))
                          + (0.0 if satellite_db is None else np.asarray(satellite_db))}
    ref = np.array([6378137.0, 0.0, 0.0])
    real["sat_pos"] = ref + 2.0e7 * (np.cos(el)[..., None] * np.array([0.0, 1.0, 0.0])
                                     + np.sin(el)[..., None] * np.array([1.0, 0.0, 0.0]))
    return real, ref


def test_a_signal_falling_faster_with_elevation_gets_its_own_cn0_table():
    """L2W 10 dB further down at the horizon than L1C: the fit keeps L1C's pattern as the antenna's and writes
    L2W's offset by the angle from boresight, -3 dB at boresight to -13 dB at 90 deg, within 0.5 dB at every node;
    the scenario fragment carries it as a table."""
    real, ref = _two_signal_cn0(10.0)
    p = twin.fit_parameters(real, ref)
    off, val = p["cn0_offset_table"]["L2W"]
    expected = -3.0 - 10.0 * (np.array(off) / 90.0) ** 2
    np.testing.assert_allclose(val, expected, atol=0.5)
    entry = twin.cn0_offset_entries(p)["L2W"]
    assert entry["off_boresight_deg"] == list(off) and "offset_db = [" in twin.toml_fragment(p)


def test_signals_with_one_pattern_keep_a_single_offset():
    real, ref = _two_signal_cn0(0.0)
    p = twin.fit_parameters(real, ref)
    assert "cn0_offset_table" not in p and p["cn0_offset_db"]["L2W"] == pytest.approx(-3.0, abs=0.2)
    assert twin.cn0_offset_entries(p) == {"L2W": p["cn0_offset_db"]["L2W"]}
    assert "satellite_cn0_offset_db" not in p     # satellites alike: no offsets


def test_each_satellites_own_cn0_is_recovered_and_the_levels_stay():
    """Satellites' L2W 4 dB apart (centred): the fit gives each its offset within 0.25 dB, L1C none (its
    satellites are alike), and the L2W level and L1C pattern as without them; the fragment carries the table."""
    sat_db = np.linspace(-2.0, 2.0, 10)
    real, ref = _two_signal_cn0(0.0, satellite_db=sat_db)
    p = twin.fit_parameters(real, ref)
    got = p["satellite_cn0_offset_db"]
    assert set(got) == {"L2W"}
    np.testing.assert_allclose([got["L2W"][f"G{k + 1:02d}"] for k in range(10)], sat_db, atol=0.25)
    assert p["cn0_offset_db"]["L2W"] == pytest.approx(-3.0, abs=0.3)
    assert p["cn0_zenith_dbhz"] == pytest.approx(48.0, abs=0.3)
    fragment = tomllib.loads(twin.toml_fragment(p))["gnss"]
    assert fragment["satellite_cn0_offset_db"]["L2W"]["G10"] == pytest.approx(got["L2W"]["G10"], abs=0.005)


@pytest.mark.slow
def test_twin_of_kms3_with_fit(tmp_path, capsys):
    out = tmp_path / "twin"
    assert main(["twin", str(KMS3_OBS), "--nav", str(KMS3_NAV), "-o", str(out), "--fit"]) == 0
    report = capsys.readouterr().out
    assert "visibility agreement" in report and (out / "report.md").read_text() == report
    fid = json.loads((out / "fidelity.json").read_text())
    c = fid["default"]
    assert c["visibility_agreement"] > 0.95 and c["tracked_real_not_twin"] == 0
    # only low satellites differ: GPS+BDS alone below 2 deg; with the five systems one satellite at 5.5 deg
    # that the twin tracks and the receiver did not
    assert c["disagreement_max_elevation_deg"] < 6.0
    # the horizon profile: the twin predicted from the default twin cut by the profile is what the calibrated
    # twin (simulated with the profile as [[environment.body_mask]]) tracks
    # twin (simulated with the profile as [[environment.body_mask]] and the fitted acquisition delay) tracks;
    # the acquisition model predicted on the default twin's grid is what the calibrated twin scores
    hz, c, acq = fid["horizon"]["in_sample"], fid["fitted"], fid["acquisition"]
    assert acq["agreement_without"] == hz["agreement"] >= 0.98
    assert c["visibility_agreement"] == acq["agreement_with"] >= hz["agreement"]
    # C24 rises at 120 s (0.8 deg) and is first tracked one epoch later, at 0.9 deg
    assert [(r["sat"], r["delay_s"]) for r in acq["rising"]] == [("C24", 30.0)] and acq["delay_s"] == 30.0
    assert fid["holdout"]["visibility_agreement"] > 0.97       # fitted on the first half, checked on the second
    ratios = {k: [x for v in fid[k]["code_noise_ratio"].values() for x in v if x] for k in ("default", "fitted")}
    ratios["holdout"] = [x for v in fid["holdout"]["code_noise_ratio"].values() for x in v if x]
    assert np.median(ratios["default"]) > 2.0                      # simkit's defaults: a noisier receiver
    assert 0.85 < np.median(ratios["fitted"]) < 1.15                # the calibrated twin, in sample
    assert 0.8 < np.median(ratios["holdout"]) < 1.3                 # out of sample
    # the equal-count bins with their standard errors (twin over 4 seeds): in sample the ratios scatter about 1 as
    # their standard errors say; out of sample on both splits no more than sampling and a few bins beyond two
    # standard errors (KMS3's 9 minutes: no bin resolves 20 %, noted in docs/real_data.md)
    ins = fid["noise"]["in_sample"]["code_noise"]
    assert ins["twin_realisations"] == 4 and {"G1C", "G2C"} <= set(ins["signals"])   # GLONASS: each k's frequency
    sm = ins["summary"]
    assert sm["bins"] >= 20 and sm["chi2_per_bin"] < 1.5 and 0.9 < sm["median_ratio"] < 1.1
    assert sm["within"] >= sm["expected_within_if_equal"] - 3
    for b in (b for v in ins["signals"].values() for b in v["bins"]):
        assert b["real_rel_se"] >= b["real_rel_se_series"] > 0 and b["twin_n_eff"] > 2 * b["real_n_eff"]
    for key, split in (("holdout", "half"), ("holdout_interleaved", "interleaved")):
        h = fid[key]
        assert h["split"] == split and h["code_model"] == "smooth"
        sm = h["noise"]["code_noise"]["summary"]
        assert sm["chi2_per_bin"] < 3.0 and 0.8 < sm["median_ratio"] < 1.25 and sm["beyond_two_se"] <= 3
        assert h["noise"]["code_noise"]["real_drift"]["bins"] == sm["bins"]
    assert fid["holdout_interleaved"]["checked_epochs"] == 6          # 19 epochs: blocks of 6-7, the middle one
    assert "twin equal to the receiver" in report and "Out of sample, interleaved split" in report
    fragment = tomllib.loads((out / "fitted.toml").read_text())
    assert set(fragment["gnss"]["code_error_scale"]) == set(fid["signals"])
    assert len(fragment["environment"]["body_mask"][0]["azimuth_deg"]) == 72
    assert fragment["gnss"]["acquisition"] == {"delay_s": 30.0}
    te = fragment["gnss"]["truth_errors"]
    sis = fid["sisre_troposphere"]["systems"]
    assert {"G", "C", "C_geo"} <= set(sis) and 0.3 < sis["G"]["sisre_m"] < 1.5     # GPS broadcast: 0.5-1 m
    assert te["gps_clock_sigma_m"] == pytest.approx(0.5 * sis["G"]["sisre_m"] / 0.53, rel=0.02)
    assert "tropo_zwd_random_walk_m_per_sqrt_h" not in te
    assert "Broadcast orbit/clock (SISRE)" in report and "Acquisition of rising satellites" in report
    for name in ("tracked.png", "code_noise.png", "twin.h5", "twin_fit.h5", "real.h5"):
        assert (out / name).is_file()


@pytest.mark.slow
def test_calibrated_twin_of_a_static_station_with_cn0(tmp_path):
    """CN00 (Trimble NetR9, 24 h at 30 s, GPS L1C + L2W with C/N0, its own broadcast file) against its calibrated
    twin: the targets of the real-data comparison, in sample and on both out-of-sample splits (fitted on half the
    day, checked on the other half; fitted on alternate blocks, checked on the others): visibility agreement >= 98 %;
    every equal-count code-noise bin within 20 % and resolving 20 % (standard error <= 10 %); the C/N0 bin means
    of both signals within 1.5 dB-Hz RMS. L2W falls faster with elevation than L1C: its own offset table."""
    out = tmp_path / "twin"
    assert main(["twin", str(CN00_OBS), "--nav", str(CN00_NAV), "-o", str(out), "--fit", "--no-plots"]) == 0
    fid = json.loads((out / "fidelity.json").read_text())
    fragment = tomllib.loads((out / "fitted.toml").read_text())["gnss"]
    assert isinstance(fragment["cn0_offset_db"]["L2W"], dict)
    assert set(fragment["satellite_cn0_offset_db"]) == {"L1C", "L2W"}
    assert fid["fitted"]["visibility_agreement"] >= 0.98
    for key, noise in (("in", fid["noise"]["in_sample"]), ("holdout", fid["holdout"]["noise"]),
                       ("holdout_interleaved", fid["holdout_interleaved"]["noise"])):
        if key != "in":
            assert fid[key]["visibility_agreement"] >= 0.98, key
        sm = noise["code_noise"]["summary"]
        assert sm["bins"] == 12 and sm["within"] == 12 and sm["resolved"] == 12, (key, sm)
        for signal in ("L1C", "L2W"):
            assert noise["cn0"][signal]["rms_dbhz"] <= 1.5, (key, signal)


def test_the_twin_shows_its_progress(tmp_path, capsys):
    """Each simulated twin shows its progress bar on stderr (`twin --fit` of KMS3 was 27 s of silence, then the
    report)."""
    out = tmp_path / "twin"
    assert main(["twin", str(KMS3_OBS), "--nav", str(KMS3_NAV), "-o", str(out), "--no-plots"]) == 0
    err = capsys.readouterr().err
    assert "twin: " in err and "sample/s" in err


def test_twin_needs_a_reference_and_navigation(tmp_path, capsys):
    from realdata_helpers import BERLIN_NAV, BERLIN_OBS

    assert main(["twin", str(BERLIN_OBS), "--nav", str(BERLIN_NAV), "-o", str(tmp_path / "t"), "--no-plots"]) == 2
    assert "no reference position" in capsys.readouterr().err


def test_the_fitted_fragment_is_a_valid_gnss_section(tmp_path):
    """The fragment merged into the twin's scenario loads (every key known, every value in range)."""
    from simkit.scenario import load

    p = dict(twin.DEFAULTS, code_error_scale={"L1C": 0.2}, mp_signal_correlation_time_s={"L1C": 12.5})
    fragment = tomllib.loads(twin.toml_fragment(p))
    real = {"t": np.arange(20) * 30.0, "signals": ["L1C"], "start": (2213, 295200.0)}
    sc = twin.scenario(real, np.array([3516213.438, 781859.8595, 5246037.966]), [str(KMS3_NAV)], 5.0, {}, 1)
    sc["gnss"].update({k: v for k, v in fragment["gnss"].items() if k != "antenna"})
    sc["gnss"]["antenna"] = fragment["gnss"]["antenna"]
    loaded = load(sc)
    assert loaded.gnss.code_error_scale == {"L1C": 0.2}
    assert loaded.gnss.multipath.signal_correlation_time_s == {"L1C": 12.5}
    tables = {"L1C": ((5.0, 45.0), (2.0, 1.0)), "L2W": 0.5}
    fragment = tomllib.loads(twin.toml_fragment(dict(twin.DEFAULTS, code_error_scale=tables)))
    sc["gnss"]["code_error_scale"] = fragment["gnss"]["code_error_scale"]
    sc["gnss"]["signals"] = ["L1C", "L2W"]
    assert load(sc).gnss.code_error_scale == tables
    # the same parameters read back from fidelity.json (tuples become lists) give the same fragment
    as_json = json.loads(json.dumps(dict(twin.DEFAULTS, code_error_scale=tables)))
    assert twin.toml_fragment(as_json) == twin.toml_fragment(dict(twin.DEFAULTS, code_error_scale=tables))
    assert loaded.gnss.multipath.carrier_sigma_m == pytest.approx(0.01)
    # a signal's C/N0 offset by the angle from boresight: a table in the fragment, the same table loaded
    offsets = dict(twin.DEFAULTS, cn0_offset_db={"L2W": -3.0},
                   cn0_offset_table={"L2W": ((0.0, 45.0, 90.0), (-3.0, -5.5, -13.0))})
    sc["gnss"]["cn0_offset_db"] = tomllib.loads(twin.toml_fragment(offsets))["gnss"]["cn0_offset_db"]
    assert load(sc).gnss.cn0_offset_db == {"L2W": ((0.0, 45.0, 90.0), (-3.0, -5.5, -13.0))}
    as_json = json.loads(json.dumps(offsets))
    assert twin.toml_fragment(as_json) == twin.toml_fragment(offsets)


def test_the_fragment_with_truth_errors_acquisition_and_cn0_step_loads():
    from simkit.scenario import load

    p = dict(twin.DEFAULTS, iono_residual_fraction=0.2, acquisition={"delay_s": 30.0},
             cn0_report={"resolution_dbhz": 0.25},
             truth_errors={"tropo_mapping": "niell", "gps_orbit_sigma_rac_m": [0.2, 0.8, 0.5],
                           "gps_clock_sigma_m": 0.7, "bds_geo_igso_sigma_scale": 4.0})
    fragment = tomllib.loads(twin.toml_fragment(p))
    real = {"t": np.arange(20) * 30.0, "signals": ["L1C"], "start": (2213, 295200.0)}
    sc = twin.scenario(real, np.array([3516213.438, 781859.8595, 5246037.966]), [str(KMS3_NAV)], 5.0, {}, 1)
    sc["gnss"]["truth_errors"] = fragment["gnss"]["truth_errors"]
    sc["gnss"]["acquisition"] = fragment["gnss"]["acquisition"]
    sc["gnss"]["cn0_report"] = fragment["gnss"]["cn0_report"]
    g = load(sc).gnss
    assert g.acquisition.delay_s == 30.0 and g.truth_errors.iono_residual_fraction == pytest.approx(0.2)
    assert g.cn0_report.resolution_dbhz == 0.25 and g.cn0_report.sigma_db == 0.0
    assert g.truth_errors.ephemeris["G"].clock_sigma_m == pytest.approx(0.7)
    assert g.truth_errors.ephemeris["C"].geosync_scale == pytest.approx(4.0)
    # the twin's own scenario carries the same keys
    sc2 = twin.scenario(real, np.array([3516213.438, 781859.8595, 5246037.966]), [str(KMS3_NAV)], 5.0, p, 1)
    assert sc2["gnss"]["acquisition"] == {"delay_s": 30.0}
    assert sc2["gnss"]["cn0_report"] == {"resolution_dbhz": 0.25}
    assert sc2["gnss"]["truth_errors"]["gps_clock_sigma_m"] == 0.7


@pytest.mark.slow
def test_twin_of_a_moving_receiver_along_its_own_spp(tmp_path, capsys):
    """Berlin (a car, GPS L1 C/A, 5 Hz, 12 s test copy): import, SPP, then the twin along the SPP path."""
    from realdata_helpers import BERLIN_NAV, BERLIN_OBS

    real = tmp_path / "real.h5"
    assert main(["import", str(BERLIN_OBS), "--nav", str(BERLIN_NAV), "-o", str(real)]) == 0
    assert main(["solve", str(real), "--filter", "spp", "--set", 'estimator.systems="G"']) == 0
    shadowed = tmp_path / "twin"
    assert main(["twin", str(BERLIN_OBS), "--nav", str(BERLIN_NAV), "--trajectory", str(real),
                 "--trajectory-solution", "spp", "-o", str(shadowed), "--fit", "--no-plots"]) == 0
    capsys.readouterr()
    # the calibrated twin without the shadowing term: run beside it into without_shadowing/
    out = shadowed / "without_shadowing"
    fid = json.loads((shadowed / "fidelity.json").read_text())["without_shadowing"]
    fid["default"] = json.loads((shadowed / "fidelity.json").read_text())["default"]
    assert "horizon" in fid and fid["horizon"] is None
    # the levelled path: one height, the SPP's horizontal positions
    rows = [r.split(",") for r in (shadowed / "trajectory.csv").read_text().splitlines() if r[0].isdigit()]
    assert len({r[4] for r in rows}) == 1 and len(rows) > 50
    # the fitted gain pattern and C/N0 offsets bring the twin's C/N0 per elevation bin towards the receiver's (in
    # sample; GPS L1 C/A and GLONASS G1 C/A: 12 s of a street, where one pattern cannot be both systems' blockage)
    def rms(run):
        return np.sqrt(np.mean(np.square(list(fid[run]["cn0_rms_difference_dbhz"].values()))))
    assert set(fid["fitted"]["cn0_rms_difference_dbhz"]) == {"L1C", "G1C"}
    assert rms("fitted") < 0.75 * rms("default")
    # the noise checks: C/N0 and code noise of both systems with their standard errors (GLONASS with each
    # satellite's frequency from the navigation records)
    for key in ("holdout", "holdout_interleaved"):
        n = fid[key]["noise"]
        assert set(n["cn0"]) == {"L1C", "G1C"} and set(n["code_noise"]["signals"]) == {"L1C", "G1C"}
        for c in n["cn0"].values():
            assert c["rms_dbhz"] ** 2 == pytest.approx(c["bias_dbhz"] ** 2 + c["scatter_dbhz"] ** 2)
            assert c["rms_se_dbhz"] > 0
    fragment = tomllib.loads((out / "fitted.toml").read_text())
    assert "gain_pattern" in fragment["gnss"]["antenna"][0] and "environment" not in fragment
    assert "shadowing" not in fragment["gnss"]
    # a drive's street-shadowing channel (docs/shadowing.md): in the fragment, in the calibrated twin's truth, and
    # the splits' real file against itself beside the twin. Its C/N0 is random: one twin's bin means over 12 s of
    # one to three satellites per bin are not the receiver's, but the twins pooled are within their sampling
    fid = json.loads((shadowed / "fidelity.json").read_text())
    assert fid["reference"].startswith("moving")
    assert "C/N0 with and without the street-shadowing term" in (shadowed / "report.md").read_text()
    for c in fid["noise"]["in_sample"]["cn0"].values():
        assert c["chi2_per_bin"] < 2.0
    out = shadowed
    fragment = tomllib.loads((out / "fitted.toml").read_text())
    sh = fragment["gnss"]["shadowing"]
    assert len(sh["shadowed_probability"]) == len(sh["elevation_deg"]) and len(sh["dwell_s"]) == 3
    with open_dataset(out / "twin_fit.h5") as ds:
        g = read_gnss(ds, antennas=0, obs=("cn0",), truth=("shadow_state",))
    assert {0, 1} <= set(np.unique(g.truth["shadow_state"]))
    # the u-blox writes whole dB-Hz: so does the calibrated twin ([gnss.cn0_report])
    assert fragment["gnss"]["cn0_report"] == {"resolution_dbhz": 1.0}
    for c in g.obs["cn0"].values():
        assert np.isfinite(c).any() and np.array_equal(c[np.isfinite(c)], np.round(c[np.isfinite(c)]))
    for key in ("holdout", "holdout_interleaved"):
        for c in fid[key]["noise"]["cn0"].values():
            assert "real_against_itself" in c and c["spread_rms_db"] is not None


def test_twin_refuses_no_realisations_and_an_unknown_code_model(tmp_path, capsys):
    assert main(["twin", str(KMS3_OBS), "--nav", str(KMS3_NAV), "-o", str(tmp_path / "t"), "--no-plots",
                 "--realisations", "0"]) == 2
    assert "--realisations" in capsys.readouterr().err
    assert not (tmp_path / "t" / "fidelity.json").exists()
    with pytest.raises(SystemExit):
        main(["twin", str(KMS3_OBS), "--nav", str(KMS3_NAV), "-o", str(tmp_path / "u"), "--code-model", "spline"])
    from simkit.errors import InputError

    with pytest.raises(InputError, match="code_model"):
        twin._calibrate({}, None, [], 0.0, 1, tmp_path / "x.h5", False, default=(None, None, None),
                        code_model="spline")
