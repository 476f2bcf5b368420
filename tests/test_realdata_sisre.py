"""SISRE and zenith troposphere from ionosphere-free code residuals (simkit/realdata/sisre.py), validated on
simulated files whose truth is known: the twin of the KMS3 test file (its broadcast sky and epochs, GPS L1C/L2W and
BDS B1I/B3I) with given broadcast orbit/clock errors and troposphere, geodetic-receiver code noise and multipath.
The fit must recover the configured SISRE and the file's own zenith delay error within its stated uncertainty,
and choose the mapping function the truth used."""
from __future__ import annotations

import numpy as np
import pytest

import simkit
from simkit.gnss.tropo_truth import niell_mapping
from simkit.gnss.truth_config import realistic_defaults
from simkit.io import open_dataset, read_gnss
from simkit.realdata import importer, sisre, twin

from realdata_helpers import KMS3_HEADER_POS, KMS3_NAV, KMS3_OBS

GPS_CLOCK = 1.2          # m, more than the default 0.5: the fit must follow the file, not the defaults
BDS_ORBIT = [0.3, 1.2, 0.8]


@pytest.fixture(scope="module")
def kms3_real():
    imp = importer.import_rinex(KMS3_OBS, [KMS3_NAV], None, None)
    return twin.real_arrays(imp)


def _simulate(real, tmp, seed, truth_errors):
    r = {**real, "signals": ["L1C", "L2W", "B1I", "B3I"]}
    sc = twin.scenario(r, KMS3_HEADER_POS, [KMS3_NAV], 0.0, {"mp_code_sigma_m": 0.5, "mp_correlation_time_s": 60.0,
                                                            "code_error_scale": {"L2W": 0.5, "B3I": 0.7}}, seed)
    sc["gnss"]["truth_errors"] = dict(truth_errors)
    out = simkit.run(sc, out=tmp / f"sim{seed}.h5", force=True)
    arr = twin.file_arrays(out)
    with open_dataset(out) as ds:
        g = read_gnss(ds, antennas=0, truth=("orbit_range_error", "troposphere_model_error"))
        clock_error = ds["gnss/truth/satellite_clock_error"][:]
    return arr, g.truth["orbit_range_error"] + clock_error, g.truth["troposphere_model_error"]


def _true_zenith(res, tropo_error, mapping):
    """The file's zenith delay error: its troposphere model error, less the mapping difference, over m(el)."""
    ok = np.isfinite(res["y"])
    el = res["el"][ok]
    from simkit.gnss import atmosphere
    zh, zw = atmosphere.saastamoinen_zenith(res["lat"], res["h"])
    if mapping == "niell":
        m_h, m_w = niell_mapping(res["lat"], res["h"], el, res["doy"])
        shift, m = zh * (m_h - 1 / np.sin(el)) + zw * (m_w - 1 / np.sin(el)), 0.5 * (m_h + m_w)
    else:
        shift, m = 0.0, 1 / np.sin(el)
    return float(np.median((tropo_error[ok] - shift) / m))


def _realized_sisre(res, range_error, letter):
    ok = np.isfinite(res["y"])
    means = [range_error[ok[:, s], s].mean() for s in range(ok.shape[1])
             if res["system"][s] == letter and ok[:, s].sum() >= sisre.MIN_EPOCHS]
    return float(np.std(means, ddof=1))


def test_the_default_sisre_is_the_documented_one():
    d = realistic_defaults()
    # docs/truth_errors.md: 0.53 m GPS, 0.97 m BDS (Montenbruck et al. 2018 weights)
    assert sisre.sisre_of(d["gps_orbit_sigma_rac_m"], d["gps_clock_sigma_m"], "G") == pytest.approx(0.53, abs=0.005)
    assert sisre.sisre_of(d["bds_orbit_sigma_rac_m"], d["bds_clock_sigma_m"], "C") == pytest.approx(0.97, abs=0.005)
    assert sisre.sisre_of([1.0, 0.0, 0.0], 0.0, "G") == pytest.approx(0.98)
    assert sisre.sisre_of([0.0, 7.0, 0.0], 0.0, "G") == pytest.approx(1.0)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [3, 4])
def test_sisre_and_niell_troposphere_recovered_from_a_simulated_station(kms3_real, tmp_path, seed):
    arr, range_error, tropo_error = _simulate(kms3_real, tmp_path, seed, {
        "gps_clock_sigma_m": GPS_CLOCK, "bds_orbit_sigma_rac_m": BDS_ORBIT, "tropo_mapping": "niell",
        "tropo_zhd_sigma_m": 0.1, "tropo_zwd_sigma_m": 0.1, "iono_residual_fraction": 0.5})
    res = sisre.residuals(arr, KMS3_HEADER_POS)
    fit = sisre.fit(res)
    assert fit["tropo_mapping"] in ("niell", None)      # 9 minutes with few low passes rarely decide it
    dz = _true_zenith(res, tropo_error, "niell")
    h = fit["hypotheses"]["niell"]
    assert abs(h["zenith_delay_error_m"] - dz) < 2.5 * h["zenith_delay_error_sigma_m"], (fit, dz)
    d = realistic_defaults()
    configured = {"G": sisre.sisre_of(d["gps_orbit_sigma_rac_m"], GPS_CLOCK, "G"),
                  "C": sisre.sisre_of(BDS_ORBIT, d["bds_clock_sigma_m"], "C")}
    for letter in "GC":
        s = fit["systems"][letter]
        realized = _realized_sisre(res, range_error, letter)
        print(letter, s, "realized", realized, "configured", configured[letter], "dz", fit["zenith_delay_error_m"], dz)
        assert abs(s["sisre_m"] - configured[letter]) < 2.5 * s["sisre_sigma_m"]
        assert abs(s["sisre_m"] - realized) < 2.5 * s["sisre_sigma_m"]
    keys, notes = sisre.parameters(fit, 540.0)
    assert keys["gps_clock_sigma_m"] / keys["gps_orbit_sigma_rac_m"][1] == pytest.approx(0.5 / 0.6)
    assert any("random_walk" in n for n in notes)


@pytest.mark.slow
def test_a_truth_mapped_like_the_model_gets_its_offset_back_and_is_never_called_niell(kms3_real, tmp_path):
    arr, _, tropo_error = _simulate(kms3_real, tmp_path, 5, {"tropo_mapping": "model", "tropo_zhd_sigma_m": 0.5,
                                                              "tropo_zwd_sigma_m": 0.2})
    res = sisre.residuals(arr, KMS3_HEADER_POS)
    fit = sisre.fit(res)
    assert fit["tropo_mapping"] in ("model", None)
    dz = _true_zenith(res, tropo_error, "model")
    h = fit["hypotheses"]["model"]
    assert abs(h["zenith_delay_error_m"] - dz) < 2.5 * h["zenith_delay_error_sigma_m"], (fit, dz)
    assert abs(dz) > 0.1     # an offset the test can see


def test_too_few_passes_leave_the_defaults(kms3_real):
    r = {**kms3_real, "obs": {k: {s: v[:, :0] if False else v for s, v in d.items()} for k, d in kms3_real["obs"].items()}}
    r["signals"] = ["L1C"]          # no second frequency: no ionosphere-free code
    res = sisre.residuals(r, KMS3_HEADER_POS)
    assert sisre.fit(res) is None
    keys, notes = sisre.parameters(None, 540.0)
    assert keys == {} and "defaults kept" in notes[0]


def test_geosynchronous_bds_satellites_get_their_scaled_sigma_and_the_same_draws():
    from simkit.gnss.ephemeris_errors import EphemerisErrors
    from simkit.gnss.truth_config import EphemerisErrorConfig

    cfg = {"C": EphemerisErrorConfig((0.3, 1.2, 0.8), 0.9, 3600.0, geosync_scale=3.0),
           "G": EphemerisErrorConfig((0.15, 0.6, 0.4), 0.5, 7200.0, geosync_scale=3.0)}
    sats = ["C05", "C08", "C30", "G05"]
    plain = EphemerisErrors(1, sats, cfg)
    typed = EphemerisErrors(1, sats, cfg, ["GEO", "IGSO", "MEO", "MEO"])
    week, sow = np.full(5, 2213), 331200.0 + 30.0 * np.arange(5)
    a, _ = plain.at(week, sow, np.arange(4))
    b, _ = typed.at(week, sow, np.arange(4))
    np.testing.assert_allclose(b[:, :2], 3.0 * a[:, :2], rtol=1e-12)
    np.testing.assert_array_equal(b[:, 2:], a[:, 2:])       # MEO, and GPS (the scale is BDS's key only)


def test_the_geo_igso_scale_is_a_checked_scenario_key(tmp_path):
    from simkit.errors import ScenarioError
    from simkit.gnss.truth_config import parse_truth_errors
    from simkit.section import Section

    cfg = parse_truth_errors(Section({"bds_geo_igso_sigma_scale": 4.0}, "gnss.truth_errors"))
    assert cfg.ephemeris["C"].geosync_scale == 4.0 and cfg.ephemeris["G"].geosync_scale == 1.0
    with pytest.raises(ScenarioError, match="bds_geo_igso_sigma_scale"):
        parse_truth_errors(Section({"bds_geo_igso_sigma_scale": -1.0}, "gnss.truth_errors"))
