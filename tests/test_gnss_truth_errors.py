"""Truth-side errors the receiver's models do not remove (docs/truth_errors.md): the pieces against RTKLIB (Niell
mapping, pierce point, IONEX reading and interpolation), closure of the stored terms against the receiver's models,
the "none" switch, the statistics of the random terms, and clear errors for bad keys and malformed IONEX files."""

import gzip
import shutil

import numpy as np
import pyrtklib as rtk
import pytest

from simkit import frames
from simkit.earth import C_LIGHT
from simkit.errors import DataFileError, ScenarioError
from simkit.gnss import parse_config
from simkit.gnss.atmosphere import F_L1, reference_frequency
from simkit.gnss.ephemeris_errors import EphemerisErrors
from simkit.gnss.ionex import IONO_CONSTANT, TECU, read_ionex, slant_factor
from simkit.gnss.iono_truth import TruthIonosphere, pierce_point
from simkit.gnss.tropo_truth import TruthTroposphere, niell_mapping
from simkit.gnss.truth_config import EphemerisErrorConfig
from simkit.section import Section

from conftest import DATA
from test_gnss_observables import make, run

IONEX = DATA / "ionex" / "synth1580.16i"
WEEK = 1900


def _arr(values):
    a = rtk.Arr1Ddouble(len(values))
    for i, v in enumerate(values):
        a[i] = float(v)
    return a


def test_niell_mapping_matches_rtklib_tropmapf():
    rs = np.random.default_rng(2)
    wet, worst = rtk.Arr1Ddouble(1), 0.0
    for _ in range(300):
        lat, h, el = rs.uniform(-1.5, 1.5), rs.uniform(-100.0, 3000.0), rs.uniform(0.05, 1.57)
        t = rtk.gpst2time(int(rs.integers(1900, 2400)), rs.uniform(0.0, 604800.0))
        m_h = rtk.tropmapf(t, _arr([lat, 0.3, h]), _arr([0.5, el]), wet)
        ours = niell_mapping(lat, h, el, rtk.time2doy(t))
        worst = max(worst, abs(ours[0] - m_h), abs(ours[1] - wet[0]))
    print(f"\nNiell mapping vs RTKLIB tropmapf: max |diff| {worst:.1e}")
    assert worst < 1e-12


def test_pierce_point_matches_rtklib_ionppp():
    rs = np.random.default_rng(3)
    out, worst = rtk.Arr1Ddouble(2), 0.0
    for _ in range(300):
        lat, lon, az, el = rs.uniform(-1.5, 1.5), rs.uniform(-3.1, 3.1), rs.uniform(0, 2 * np.pi), rs.uniform(0.05, 1.5)
        rtk.ionppp(_arr([lat, lon, 0.0]), _arr([az, el]), 6378.1363e3, 350e3, out)
        lat_p, lon_p = pierce_point(lat, lon, az, el)
        worst = max(worst, abs(lat_p - out[0]), abs(np.angle(np.exp(1j * (lon_p - out[1])))))
    assert worst < 1e-12


@pytest.mark.parametrize("gz", [False, True])
def test_ionex_slant_delay_matches_rtklib_iontec(tmp_path, gz):
    """The synthetic map read by our parser and by RTKLIB's readtec; slant delays on L1 at random geometries and
    times agree. RTKLIB labels the UT epochs as GPST, so it is asked at GPST - 17 s (the 2016 leap seconds)."""
    path = IONEX
    if gz:
        path = tmp_path / "synth1580.16i.gz"
        with open(IONEX, "rb") as src, gzip.open(path, "wb") as dst:
            shutil.copyfileobj(src, dst)
    maps = read_ionex(path)
    assert (maps.first_week, maps.first_sow) == (WEEK, 86400.0 + 8 * 3600.0 + 17.0)
    assert maps.tec_tecu.shape == (4, 36, 37) and np.isnan(maps.tec_tecu).sum() == 1
    nav = rtk.nav_t()
    rtk.readtec(str(IONEX), nav, 0)
    rs = np.random.default_rng(1)
    delay, var, worst, compared = rtk.Arr1Ddouble(1), rtk.Arr1Ddouble(1), 0.0, 0
    for _ in range(400):
        lat, lon, az, el = rs.uniform(-1.3, 1.3), rs.uniform(-3.1, 3.1), rs.uniform(0, 2 * np.pi), rs.uniform(0.1, 1.5)
        sow = maps.first_sow + rs.uniform(0.0, 6 * 3600.0)
        ok = rtk.iontec(rtk.gpst2time(WEEK, sow - 17.0), nav, _arr([lat, lon, 100.0]), _arr([az, el]), 1, delay, var)
        lat_p, lon_p = pierce_point(lat, lon, az, el, maps.base_radius_m, maps.height_m)
        ours = (IONO_CONSTANT * TECU / F_L1**2 * maps.vtec(WEEK, sow, lat_p, lon_p)
                * slant_factor(el, maps.base_radius_m, maps.height_m))
        if ok and np.isfinite(ours):
            worst, compared = max(worst, abs(ours - delay[0])), compared + 1
    print(f"\nIONEX slant delay vs RTKLIB iontec: max |diff| {worst:.1e} m over {compared}")
    assert compared > 350 and worst < 1e-9


def _corrupt(tmp_path, edit):
    lines = IONEX.read_text().splitlines(keepends=True)
    path = tmp_path / "bad.16i"
    path.write_text("".join(edit(lines)))
    return path


def _replace_label(label, new_data):
    def edit(lines):
        return [f"{new_data:<60s}{label}\n" if ln[60:].strip() == label else ln for ln in lines]
    return edit


@pytest.mark.parametrize("edit, where, words", [
    (lambda ls: ls[1:], 1, "IONEX VERSION / TYPE"),
    (_replace_label("IONEX VERSION / TYPE", "     2.0            I"), 1, "version 2 is not supported"),
    (lambda ls: [ln for ln in ls if "BASE RADIUS" not in ln], None, "'BASE RADIUS'"),
    (lambda ls: [ln for ln in ls if "END OF HEADER" not in ln], None, "file ends early"),
    (_replace_label("MAP DIMENSION", "     3"), 12, "only 2-D maps"),
    (_replace_label("LAT1 / LAT2 / DLAT", "    87.5 -87.5   0.0"), 14, "whole number"),
    (_replace_label("EPOCH OF FIRST MAP", "  2016    13     6     8     0     0"), 5, "not a valid epoch"),
    (_replace_label("# OF MAPS IN FILE", "     5"), 8, "the file holds 4"),
    (lambda ls: ls[:21] + ["   50   5x   50\n"] + ls[22:], 22, "16I5"),
    (lambda ls: ls[:21] + ls[22:], 24, "expected 37 TEC values, got 21 before the line labelled"),
    (lambda ls: ls[:20] + ["    88.0-180.0 180.0  10.0 350.0                            LAT/LON1/LON2/DLON/H\n"]
     + ls[21:], 21, "not on the header's grid"),
    (lambda ls: ls[:-1], None, "file ends early"),
])
def test_malformed_ionex_is_one_clear_error_naming_the_line(tmp_path, edit, where, words):
    path = _corrupt(tmp_path, edit)
    with pytest.raises(DataFileError) as err:
        read_ionex(path)
    text = str(err.value)
    assert text.startswith(str(path)) and words in text, text
    if where is not None:
        assert text.startswith(f"{path}:{where}:"), text


def test_missing_ionex_file_is_a_data_file_error(tmp_path):
    with pytest.raises(DataFileError, match="cannot read IONEX file"):
        read_ionex(tmp_path / "none.16i")


def _models_at(out, sim):
    """Saastamoinen (1/sin el) from RTKLIB's tropmodel and GPS Klobuchar from RTKLIB's ionmodel at the stored
    antenna positions and angles, for a few epochs and every tracked GPS satellite."""
    ant, el, az = out["truth/antenna_pos_ecef"], out["truth/elevation"], out["truth/azimuth"]
    alpha, beta = sim.iono["G"]
    ion = _arr(list(alpha) + list(beta))
    rows = []
    for m in range(0, ant.shape[0], 10):
        for a in range(ant.shape[1]):
            lla = frames.ecef_to_lla(ant[m, a][None])[0]
            t = rtk.gpst2time(WEEK, 86400.0 + 10 * 3600.0 + m)
            for s in np.flatnonzero(np.isfinite(el[m, a])):
                azel = _arr([az[m, a, s], el[m, a, s]])
                trop = rtk.tropmodel(t, _arr(lla), azel, 0.5)
                iono = rtk.ionmodel(t, ion, _arr(lla), azel) if sim.sat_ids[s][0] == "G" else np.nan
                rows.append((m, a, s, trop, iono))
    return rows


def test_stored_terms_are_the_receivers_models_plus_the_stored_errors():
    """truth - *_model_error is exactly what a receiver's models give (RTKLIB tropmodel / ionmodel), the true
    clock term minus its error is the broadcast clock of /gnss/sat_clock, and every departure is really on."""
    sim = make(duration=60.0)
    out = run(sim)
    worst_t = worst_i = 0.0
    for m, a, s, trop, iono in _models_at(out, sim):
        worst_t = max(worst_t, abs(out["truth/troposphere"][m, a, s] - out["truth/troposphere_model_error"][m, a, s]
                                   - trop))
        if np.isfinite(iono):
            model = out["truth/L1C/ionosphere"][m, a, s] - out["truth/ionosphere_model_error"][m, a, s]
            worst_i = max(worst_i, abs(model - iono))
    print(f"\ntruth - model error vs RTKLIB: troposphere {worst_t:.1e} m, ionosphere {worst_i:.1e} m")
    assert worst_t < 1e-6 and worst_i < 1e-6
    brd = -C_LIGHT * out["sat_clock"][:, None, :]
    true_clock = out["truth/satellite_clock"] - out["truth/satellite_clock_error"][:, None, :]
    ok = np.isfinite(out["truth/range"])
    assert ok.sum() > 500 and np.max(np.abs(true_clock - brd)[ok]) < 1e-3
    for name, floor in (("ionosphere_model_error", 0.05), ("troposphere_model_error", 0.005),
                        ("orbit_range_error", 0.05), ("satellite_clock_error", 0.05)):
        assert np.nanstd(out[f"truth/{name}"]) > floor, name


def test_none_switch_changes_exactly_the_stored_model_errors_and_no_other_stream():
    """Same seed, truth errors on and off: the noise, multipath, clock and ambiguity streams are identical, the
    "none" file has all model errors zero, and the observables differ by exactly the sum of the stored errors."""
    on, off = run(make(duration=60.0)), run(make({"truth_errors": {"model": "none"}}, duration=60.0))
    for key in ("truth/L1C/noise_code", "truth/B1I/multipath_code", "truth/receiver_clock", "obs/L1C/ambiguity",
                "truth/L2W/noise_doppler", "sat_pos_ecef", "sat_clock"):
        np.testing.assert_array_equal(on[key], off[key], err_msg=key)
    for key in ("ionosphere_model_error", "troposphere_model_error", "orbit_range_error", "orbit_error_rac",
                "satellite_clock_error"):
        assert np.all(np.nan_to_num(off[f"truth/{key}"]) == 0.0), key
    for sig, g in (("L1C", "G"), ("L2W", "G"), ("B1I", "C")):
        from simkit.gnss import signals
        scale = (reference_frequency(g) / signals.get(sig).freq_hz) ** 2
        common = (on["truth/orbit_range_error"] + on["truth/satellite_clock_error"][:, None]
                  + on["truth/troposphere_model_error"])
        code = common + on["truth/ionosphere_model_error"] * scale
        phase = common - on["truth/ionosphere_model_error"] * scale
        ok = np.isfinite(on[f"obs/{sig}/code"])
        assert ok.sum() > 100
        assert np.max(np.abs(on[f"obs/{sig}/code"] - off[f"obs/{sig}/code"] - code)[ok]) < 1e-6
        lam = C_LIGHT / signals.get(sig).freq_hz
        assert np.max(np.abs((on[f"obs/{sig}/carrier"] - off[f"obs/{sig}/carrier"]) * lam - phase)[ok]) < 1e-6


def test_orbit_and_clock_errors_have_the_configured_rms_and_jump_at_ephemeris_updates():
    cfg = {"G": EphemerisErrorConfig((0.2, 0.8, 0.5), 0.6, 7200.0), "C": EphemerisErrorConfig((0.4, 1.5, 1.0), 1.0,
                                                                                                 3600.0)}
    sats = [f"G{i:02d}" for i in range(1, 33)] + [f"C{i:02d}" for i in range(1, 46)]
    eph = EphemerisErrors(11, sats, cfg)
    sow = np.arange(0.0, 3 * 86400.0, 60.0)
    e, rate = eph.at(np.full(sow.size, WEEK), sow, np.arange(len(sats)))
    for letter, c in cfg.items():
        cols = [i for i, s in enumerate(sats) if s[0] == letter]
        rms = np.sqrt(np.mean(e[:, cols] ** 2, axis=(0, 1)))
        want = np.array(list(c.orbit_sigma_rac_m) + [c.clock_sigma_m])
        assert np.all(np.abs(rms / want - 1.0) < 0.12), (letter, rms, want)
        jumps = np.abs(np.diff(e[:, cols], axis=0))
        at_update = np.isin(np.arange(1, sow.size), np.flatnonzero(np.diff(np.floor(sow / c.interval_s + 0.5))) + 1)
        assert jumps[at_update].mean() > 20 * jumps[~at_update].mean()
    # rates are the derivatives inside an interval
    fd = np.diff(e, axis=0) / 60.0
    mid = 0.5 * (rate[1:] + rate[:-1])
    for letter, c in cfg.items():
        cols = [i for i, s in enumerate(sats) if s[0] == letter]
        inside = np.floor(sow[:-1] / c.interval_s + 0.5) == np.floor(sow[1:] / c.interval_s + 0.5)
        assert np.max(np.abs(fd - mid)[inside][:, cols]) < 1e-9
    # the same satellite, time and seed give the same error whatever else is asked
    again, _ = EphemerisErrors(11, sats, cfg).at(np.full(3, WEEK), sow[100:103], np.array([5]))
    np.testing.assert_array_equal(again[:, 0], e[100:103, 5])


def test_ionosphere_residual_has_the_configured_relative_rms():
    truth = TruthIonosphere(5, 0.5, 1000e3, 3600.0)
    rs = np.random.default_rng(0)
    n = 20000
    lla = np.stack([rs.uniform(-1.2, 1.2, n), rs.uniform(-3.1, 3.1, n), np.zeros(n)], axis=-1)[:, None]
    az, el = rs.uniform(0, 2 * np.pi, (n, 1, 1)), rs.uniform(0.2, 1.5, (n, 1, 1))
    sow = rs.uniform(0.0, 10 * 86400.0, (n, 1, 1))
    alpha, beta = (2.2352e-08, 1.4901e-08, -1.1921e-07, -5.9605e-08), (1.2493e05, 6.5536e04, -1.9661e05, 6.5536e04)
    iono, rate, klob = truth.delay("G", alpha, beta, lla, np.zeros_like(lla), az, el, 0 * az, 0 * el,
                                   np.full_like(sow, WEEK), sow, sow)
    rel = iono / klob - 1.0
    rms = np.sqrt(np.mean(rel**2))
    print(f"\nrelative ionosphere residual RMS {rms:.3f} (configured 0.5), mean {rel.mean():+.3f}")
    assert abs(rms - 0.5) < 0.08 and abs(rel.mean()) < 0.05 and np.all(iono > 0)
    assert np.allclose(TruthIonosphere(5, 0.5, 1000e3, 3600.0).delay(
        "G", alpha, beta, lla[:5], np.zeros_like(lla[:5]), az[:5], el[:5], 0 * az[:5], 0 * el[:5],
        np.full_like(sow[:5], WEEK), sow[:5], sow[:5])[0], iono[:5], rtol=0, atol=0)


def test_ionosphere_scale_multiplies_klobuchar_with_and_without_the_residual():
    """iono_scale k: without a residual the truth is exactly k x Klobuchar (its rate too); with one, the same
    field's factor times k (the residual's draws unchanged)."""
    rs = np.random.default_rng(1)
    n = 500
    lla = np.stack([rs.uniform(-1.2, 1.2, n), rs.uniform(-3.1, 3.1, n), np.zeros(n)], axis=-1)[:, None]
    az, el = rs.uniform(0, 2 * np.pi, (n, 1, 1)), rs.uniform(0.2, 1.5, (n, 1, 1))
    azr, elr = rs.normal(0, 1e-4, (n, 1, 1)), rs.normal(0, 1e-4, (n, 1, 1))
    sow = rs.uniform(0.0, 10 * 86400.0, (n, 1, 1))
    alpha, beta = (2.2352e-08, 1.4901e-08, -1.1921e-07, -5.9605e-08), (1.2493e05, 6.5536e04, -1.9661e05, 6.5536e04)
    args = ("G", alpha, beta, lla, np.zeros_like(lla), az, el, azr, elr, np.full_like(sow, WEEK), sow, sow)
    assert not TruthIonosphere(5, 0.0, 1000e3, 3600.0).departs and TruthIonosphere(5, 0.0, 1000e3, 3600.0,
                                                                                    scale=0.2).departs
    iono, rate, klob = TruthIonosphere(5, 0.0, 1000e3, 3600.0, scale=0.2).delay(*args)
    _, k_rate, _ = TruthIonosphere(5, 0.0, 1000e3, 3600.0, scale=1.0).delay(*args)
    np.testing.assert_allclose(iono, 0.2 * klob, rtol=1e-15)
    np.testing.assert_allclose(rate, 0.2 * k_rate, rtol=0, atol=1e-13)     # differences of products: rounding
    base = TruthIonosphere(5, 0.5, 1000e3, 3600.0).delay(*args)[0]
    np.testing.assert_allclose(TruthIonosphere(5, 0.5, 1000e3, 3600.0, scale=0.2).delay(*args)[0], 0.2 * base,
                               rtol=1e-14)


def test_zenith_wet_random_walk_grows_as_configured_and_mapping_differs_at_low_elevation():
    sig = 0.01
    ends = np.array([TruthTroposphere(seed, WEEK, 86400.0, 4 * 3600.0, "niell", 0.0, 0.0, sig).walk(np.array(
        [0.0, 3600.0, 4 * 3600.0])) for seed in range(600)])
    assert np.all(ends[:, 0] == 0.0)
    for col, hours in ((1, 1.0), (2, 4.0)):
        assert abs(np.std(ends[:, col]) / (sig * np.sqrt(hours)) - 1.0) < 0.1
    tr = TruthTroposphere(1, WEEK, 86400.0, 600.0, "niell", 0.0, 0.0, 0.0)
    lat, h = np.radians(34.2), 400.0
    el = np.radians(np.array([90.0, 30.0, 10.0, 5.0]))
    diff = tr.delay(lat, h, el, 0.0) - tr.slant(lat, h, el, 0.0, 0.0, 0.0)[2]
    print(f"\nNiell minus 1/sin(el) mapping of the same zenith delays at 90/30/10/5 deg: {np.round(diff, 3)} m")
    assert abs(diff[0]) < 1e-3 and abs(diff[2]) > 0.1 and abs(diff[3]) > abs(diff[2])


def test_ionex_map_is_the_truth_ionosphere_when_given():
    sim = make({"truth_errors": {"ionex_file": str(IONEX)}}, duration=30.0)
    out = run(sim)
    maps = read_ionex(IONEX)
    ant, el, az = out["truth/antenna_pos_ecef"], out["truth/elevation"], out["truth/azimuth"]
    worst, n = 0.0, 0
    for m in (0, 29):
        lla = frames.ecef_to_lla(ant[m, 0][None])[0]
        for s in np.flatnonzero(np.isfinite(el[m, 0])):
            lat_p, lon_p = pierce_point(lla[0], lla[1], az[m, 0, s], el[m, 0, s], maps.base_radius_m, maps.height_m)
            f = reference_frequency(sim.sat_ids[s][0])
            want = (IONO_CONSTANT * TECU / f**2 * maps.vtec(WEEK, 86400.0 + 36000.0 + m, lat_p, lon_p)
                    * slant_factor(el[m, 0, s], maps.base_radius_m, maps.height_m))
            key = "truth/L1C/ionosphere" if sim.sat_ids[s][0] == "G" else "truth/B1I/ionosphere"
            worst, n = max(worst, abs(out[key][m, 0, s] - want)), n + 1
    assert n > 10 and worst < 1e-9


@pytest.mark.parametrize("table, key, words", [
    ({"model": "off"}, "gnss.truth_errors.model", "must be one of 'realistic', 'none'"),
    ({"model": "none", "gps_clock_sigma_m": 1.0}, "gnss.truth_errors.gps_clock_sigma_m", 'model = "none"'),
    ({"iono_residual_fration": 0.3}, "gnss.truth_errors.iono_residual_fration", "did you mean"),
    ({"gps_orbit_sigma_rac_m": [0.1, -0.2, 0.3]}, "gnss.truth_errors.gps_orbit_sigma_rac_m", ">= 0"),
    ({"tropo_mapping": "gmf"}, "gnss.truth_errors.tropo_mapping", "must be one of"),
    ({"bds_ephemeris_interval_s": 0.0}, "gnss.truth_errors.bds_ephemeris_interval_s", "must be in"),
    ({"ionex_file": " "}, "gnss.truth_errors.ionex_file", "expected a file path"),
    ({"iono_scale": -0.1}, "gnss.truth_errors.iono_scale", "must be in"),
    ({"model": "none", "iono_scale": 0.5}, "gnss.truth_errors.iono_scale", 'model = "none"'),
])
def test_truth_error_keys_are_validated_with_the_key_named(table, key, words):
    gnss = {"constellation": [{"source": "nominal:gps"}], "antenna": [{"lever_arm_m": [0.0, 0.0, 0.0]}],
            "truth_errors": table}
    with pytest.raises(ScenarioError) as err:
        parse_config(Section(gnss, "gnss"))
    assert key in str(err.value) and words in str(err.value), str(err.value)


def test_ionex_that_does_not_cover_the_run_is_a_scenario_error():
    with pytest.raises(ScenarioError, match="gnss.truth_errors.ionex_file: .*do not cover"):
        make({"truth_errors": {"ionex_file": str(IONEX)}}, duration=60.0, start=(WEEK, 86400.0 + 15 * 3600.0))


@pytest.mark.parametrize("content, expect", [
    ("garbage\n", "bad.16i:1: expected the first line labelled 'IONEX VERSION / TYPE'"),
    (None, "gnss.truth_errors.ionex_file: "),
    ("copy", "do not cover the run"),
])
def test_simkit_run_with_a_bad_ionex_file_is_one_line_and_writes_nothing(tmp_path, content, expect):
    from cli_errors import assert_clean_error

    bad = tmp_path / "bad.16i"
    if content == "copy":
        shutil.copyfile(IONEX, bad)
    elif content is not None:
        bad.write_text(content)
    assert_clean_error(["run", "quickstart", "-o", str(tmp_path / "q.h5"), "--set",
                        f"gnss.truth_errors.ionex_file='{bad}'"], tmp_path, expect=expect)


def test_spp_sees_metres_with_the_truth_errors_and_millimetres_once_the_stored_errors_are_removed(tmp_path):
    """Noise and multipath off: SPP (broadcast Klobuchar, Saastamoinen, broadcast orbit and clock) on the default
    truth is off by metres; the same file with each code corrected by its stored model errors closes at mm, so the
    stored terms are the whole of what the receiver's models miss."""
    import h5py

    import simkit
    from simkit.estimators.registry import DEFAULTS, spp_fixes
    from simkit.gnss import signals

    quiet = ["scenario.duration_s=20", "imu.preset=ideal", "gnss.errors.multipath=false", "gnss.errors.noise=false"]
    real = simkit.run("quickstart", out=tmp_path / "real.h5", overrides=quiet)
    fixed = tmp_path / "fixed.h5"
    shutil.copyfile(real, fixed)
    with h5py.File(fixed, "a") as f:
        t = f["gnss/truth"]
        common = t["orbit_range_error"][:] + t["satellite_clock_error"][:][:, None] + t["troposphere_model_error"][:]
        for sig in f["gnss/obs"]:
            g = signals.get(sig)
            scale = (reference_frequency(g.system) / g.freq_hz) ** 2
            code = f[f"gnss/obs/{sig}/code"]
            code[...] = code[:] - common - t["ionosphere_model_error"][:] * scale
    err = {}
    for name, path in (("real", real), ("fixed", fixed)):
        with simkit.open(path) as ds:
            fx = spp_fixes(ds, dict(DEFAULTS["spp"]))
            err[name] = np.linalg.norm(fx.pos_ecef - ds["gnss/truth/antenna_pos_ecef"][:, 0], axis=-1)
    print(f"\nSPP 3-D error: default truth RMS {np.sqrt(np.mean(err['real'] ** 2)):.2f} m, "
          f"with the stored errors removed max {err['fixed'].max() * 1e3:.2f} mm")
    assert np.sqrt(np.mean(err["real"] ** 2)) > 0.5
    assert err["fixed"].max() < 5e-3
