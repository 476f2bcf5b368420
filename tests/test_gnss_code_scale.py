"""[gnss.code_error_scale] as a table over elevation: the simulator's code sigma and code multipath are the
unscaled ones times the factor interpolated at each satellite's elevation; malformed tables are one error."""
from __future__ import annotations

import numpy as np
import pytest

from simkit.errors import ScenarioError
from simkit.io import open_dataset, read_gnss
from simkit.pipeline import run
from simkit.scenario import load


def _scenario(scale):
    return {"scenario": {"name": "cs", "start": "2022-06-08T10:00:00Z", "duration_s": 600.0, "seed": 4},
            "trajectory": {"rate_hz": 1.0, "origin": {"lat_deg": 55.0, "lon_deg": 12.5, "height_m": 50.0},
                           "initial": {"speed_m_per_s": 0.0, "heading_deg": 0.0},
                           "segment": [{"kind": "static", "duration_s": 600.0}]},
            "gnss": {"rate_hz": 1.0, "elevation_mask_deg": 5.0, "signals": ["L1C", "L2W"],
                     "constellation": [{"source": "nominal:gps"}],
                     "antenna": [{"lever_arm_m": [0.0, 0.0, 0.0]}], "code_error_scale": scale}}


def _truth(path):
    with open_dataset(path) as ds:
        g = read_gnss(ds, antennas=0, truth=("elevation", "L1C/sigma_code", "L2W/sigma_code",
                                             "L1C/multipath_code", "L2W/multipath_code"))
    return g.truth


def test_a_table_scales_code_sigma_and_multipath_by_the_factor_at_the_elevation(tmp_path):
    table = {"elevation_deg": [10.0, 25.0, 35.0], "factor": [3.0, 1.0, 0.5]}
    base = _truth(run(_scenario({}), out=tmp_path / "a.h5"))
    scaled = _truth(run(_scenario({"L1C": table, "L2W": 0.25}), out=tmp_path / "b.h5"))
    el = np.degrees(base["elevation"])
    on = np.isfinite(base["L1C/sigma_code"])
    assert on.sum() > 1000 and el[on].min() < 15 and el[on].max() > 40
    factor = np.interp(el[on], table["elevation_deg"], table["factor"])
    np.testing.assert_allclose(scaled["L1C/sigma_code"][on], base["L1C/sigma_code"][on] * factor, rtol=1e-12)
    np.testing.assert_allclose(scaled["L1C/multipath_code"][on], base["L1C/multipath_code"][on] * factor,
                               rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(scaled["L2W/sigma_code"][on], 0.25 * base["L2W/sigma_code"][on], rtol=1e-12)


@pytest.mark.parametrize("table, key, words", [
    ({"elevation_deg": [10.0, 5.0], "factor": [1.0, 2.0]}, "L1C.elevation_deg", "increasing"),
    ({"elevation_deg": [10.0, 20.0], "factor": [1.0]}, "L1C.factor", "one factor per elevation"),
    ({"elevation_deg": [10.0], "factor": [-1.0]}, "L1C.factor", ">= 0"),
    ({"elevation_deg": [10.0], "factor": [1.0], "slope": 2}, "L1C.slope", "unknown key"),
])
def test_a_malformed_table_is_one_error_naming_the_key(table, key, words):
    with pytest.raises(ScenarioError) as e:
        load(_scenario({"L1C": table}))
    assert f"gnss.code_error_scale.{key}" in str(e.value) and words in str(e.value)


def test_an_antenna_gain_pattern_sets_cn0_by_the_angle_from_boresight(tmp_path):
    """A level antenna: off-boresight = 90 deg - elevation, C/N0 = zenith + signal offset + the pattern there."""
    from simkit.gnss import signals as sigmod

    pattern = {"off_boresight_deg": [0.0, 40.0, 80.0], "gain_db": [2.0, -1.0, -15.0]}
    sc = _scenario({})
    sc["gnss"]["antenna"] = [{"lever_arm_m": [0.0, 0.0, 0.0], "gain_pattern": pattern}]
    sc["gnss"]["cn0_zenith_dbhz"] = 44.0
    with open_dataset(run(sc, out=tmp_path / "p.h5")) as ds:
        g = read_gnss(ds, antennas=0, obs=("cn0",), truth=("elevation",))
    el = np.degrees(g.truth["elevation"])
    for name in ("L1C", "L2W"):
        on = np.isfinite(g.obs["cn0"][name])
        assert on.sum() > 1000
        expected = 44.0 + sigmod.get(name).cn0_offset_db + np.interp(90.0 - el[on], pattern["off_boresight_deg"],
                                                                       pattern["gain_db"])
        np.testing.assert_allclose(g.obs["cn0"][name][on], expected, atol=1e-9)


@pytest.mark.parametrize("antenna, key, words", [
    ({"gain_pattern": {"off_boresight_deg": [0.0, 90.0], "gain_db": [0.0]}}, "gain_pattern.gain_db",
     "one gain per angle"),
    ({"gain_pattern": {"off_boresight_deg": [50.0, 10.0], "gain_db": [0.0, 1.0]}},
     "gain_pattern.off_boresight_deg", "increasing"),
    ({"gain_pattern": {"off_boresight_deg": [0.0], "gain_db": [0.0]}, "rolloff_db": 5.0}, "gain_pattern",
     "cannot be given with rolloff_db"),
])
def test_a_malformed_gain_pattern_is_one_error_naming_the_key(antenna, key, words):
    sc = _scenario({})
    sc["gnss"]["antenna"] = [{"lever_arm_m": [0.0, 0.0, 0.0], **antenna}]
    with pytest.raises(ScenarioError) as e:
        load(sc)
    assert f"gnss.antenna[0].{key}" in str(e.value) and words in str(e.value)


def test_a_receivers_cn0_offset_moves_that_signals_cn0_and_its_noise(tmp_path):
    """[gnss.cn0_offset_db] L2W = -3: L2W's C/N0 3 dB lower at every satellite-epoch, its DLL code sigma up by the
    DLL jitter's C/N0 law, L1C untouched bit for bit; without the key the arrays are those of a file without it."""
    from simkit.gnss import noise as noise_model
    from simkit.gnss import signals as sigmod

    def arrays(path):
        with open_dataset(path) as ds:
            return read_gnss(ds, antennas=0, obs=("cn0", "code"), truth=("L1C/sigma_code", "L2W/sigma_code"))

    sc = _scenario({})
    sc["gnss"]["multipath"] = {"code_sigma_m": 0.0}
    base = arrays(run(sc, out=tmp_path / "a.h5"))
    sc["gnss"]["cn0_offset_db"] = {"L2W": -3.0}
    moved = arrays(run(sc, out=tmp_path / "b.h5"))
    on = np.isfinite(base.obs["cn0"]["L2W"])
    assert on.sum() > 1000
    np.testing.assert_allclose(moved.obs["cn0"]["L2W"][on], base.obs["cn0"]["L2W"][on] - 3.0, atol=1e-9)
    assert np.array_equal(moved.obs["cn0"]["L1C"], base.obs["cn0"]["L1C"], equal_nan=True)
    assert np.array_equal(moved.truth["L1C/sigma_code"], base.truth["L1C/sigma_code"], equal_nan=True)
    g = sigmod.get("L2W")
    cfg = load(sc).gnss.noise

    def dll(cn0):
        return noise_model.dll_sigma_m(cn0, g.chip_length_m, cfg.dll_bandwidth_hz, cfg.correlator_spacing_chips,
                                       cfg.integration_time_s)
    ratio = dll(moved.obs["cn0"]["L2W"][on]) / dll(base.obs["cn0"]["L2W"][on])
    np.testing.assert_allclose(moved.truth["L2W/sigma_code"][on] / base.truth["L2W/sigma_code"][on], ratio,
                               rtol=1e-9)


def test_a_cn0_offset_table_sets_that_signals_cn0_by_the_angle_from_boresight(tmp_path):
    """[gnss.cn0_offset_db] L2W = {off_boresight_deg, offset_db}: L2W's C/N0 is the pattern's plus the table's
    value at the angle from boresight (linear in between, end values beyond); L1C untouched bit for bit."""
    from simkit.gnss import signals as sigmod

    pattern = {"off_boresight_deg": [0.0, 40.0, 80.0], "gain_db": [2.0, -1.0, -15.0]}
    table = {"off_boresight_deg": [40.0, 60.0, 80.0], "offset_db": [-1.0, -4.0, -12.0]}
    sc = _scenario({})
    sc["gnss"]["antenna"] = [{"lever_arm_m": [0.0, 0.0, 0.0], "gain_pattern": pattern}]
    sc["gnss"]["cn0_zenith_dbhz"] = 44.0
    base = run(sc, out=tmp_path / "a.h5")
    sc["gnss"]["cn0_offset_db"] = {"L2W": table}
    moved = run(sc, out=tmp_path / "b.h5")
    with open_dataset(base) as a, open_dataset(moved) as b:
        ga = read_gnss(a, antennas=0, obs=("cn0",), truth=("elevation",))
        gb = read_gnss(b, antennas=0, obs=("cn0",), truth=("elevation",))
    off = 90.0 - np.degrees(gb.truth["elevation"])
    on = np.isfinite(gb.obs["cn0"]["L2W"])
    assert on.sum() > 1000 and off[on].min() < 40.0 and off[on].max() > 80.0   # before the first node and past the last
    expected = 44.0 + sigmod.get("L2W").cn0_offset_db + np.interp(off[on], pattern["off_boresight_deg"],
                                                                   pattern["gain_db"]) \
        + np.interp(off[on], table["off_boresight_deg"], table["offset_db"])
    np.testing.assert_allclose(gb.obs["cn0"]["L2W"][on], expected, atol=1e-9)
    assert np.array_equal(gb.obs["cn0"]["L1C"], ga.obs["cn0"]["L1C"], equal_nan=True)


@pytest.mark.parametrize("table, key, words", [
    ({"off_boresight_deg": [10.0, 5.0], "offset_db": [1.0, 2.0]}, "L2W.off_boresight_deg", "increasing"),
    ({"off_boresight_deg": [10.0, 190.0], "offset_db": [1.0, 2.0]}, "L2W.off_boresight_deg", "[0, 180]"),
    ({"off_boresight_deg": [10.0, 20.0], "offset_db": [1.0]}, "L2W.offset_db", "one offset_db per"),
    ({"off_boresight_deg": [10.0], "offset_db": [-31.0]}, "L2W.offset_db", "[-30.0, 30.0]"),
    ({"elevation_deg": [10.0], "offset_db": [1.0]}, "L2W.off_boresight_deg", "missing"),
])
def test_a_malformed_cn0_offset_table_is_one_error_naming_the_key(table, key, words):
    sc = _scenario({})
    sc["gnss"]["cn0_offset_db"] = {"L2W": table}
    with pytest.raises(ScenarioError) as e:
        load(sc)
    assert f"gnss.cn0_offset_db.{key}" in str(e.value) and words in str(e.value)


def test_a_satellites_cn0_offset_moves_that_satellite_and_signal_only(tmp_path):
    """[gnss.satellite_cn0_offset_db.L2W] G05 = -4: G05's L2W C/N0 4 dB lower at every epoch it is tracked; every
    other satellite-signal bit for bit the same."""
    sc = _scenario({})
    base = run(sc, out=tmp_path / "a.h5")
    with open_dataset(base) as ds:
        g0 = read_gnss(ds, antennas=0, obs=("cn0",))
        sats = [str(x) for x in g0.sat_id]
    on = np.isfinite(g0.obs["cn0"]["L2W"])
    sat = sats[int(np.argmax(on.sum(0)))]          # the satellite tracked longest
    sc["gnss"]["satellite_cn0_offset_db"] = {"L2W": {sat: -4.0}}
    with open_dataset(run(sc, out=tmp_path / "b.h5")) as ds:
        g1 = read_gnss(ds, antennas=0, obs=("cn0",))
    k = sats.index(sat)
    assert on[:, k].sum() > 100
    np.testing.assert_allclose(g1.obs["cn0"]["L2W"][:, k][on[:, k]], g0.obs["cn0"]["L2W"][:, k][on[:, k]] - 4.0,
                               atol=1e-9)
    others = np.ones(len(sats), bool)
    others[k] = False
    assert np.array_equal(g1.obs["cn0"]["L2W"][:, others], g0.obs["cn0"]["L2W"][:, others], equal_nan=True)
    assert np.array_equal(g1.obs["cn0"]["L1C"], g0.obs["cn0"]["L1C"], equal_nan=True)


@pytest.mark.parametrize("table, key, words", [
    ({"L2W": {"G1": 1.0}}, "L2W.G1", "satellite id"),
    ({"L2W": {"G05": 40.0}}, "L2W.G05", "[-30.0, 30.0]"),
    ({"L2W": {"G99": 1.0}}, "L2W.G99", "unknown satellite"),
    ({"L5Q": {"G05": 1.0}}, "L5Q", "unknown key"),
])
def test_a_malformed_satellite_cn0_offset_is_one_error_naming_the_key(table, key, words, tmp_path):
    sc = _scenario({})
    sc["gnss"]["satellite_cn0_offset_db"] = table
    with pytest.raises(ScenarioError) as e:
        run(sc, out=tmp_path / "x.h5")
    assert f"gnss.satellite_cn0_offset_db.{key}" in str(e.value) and words in str(e.value)
    assert not (tmp_path / "x.h5").exists()


@pytest.mark.parametrize("table, words", [({"L2W": 45.0}, "[-30.0, 30.0]"), ({"L5Q": 1.0}, "unknown key"),
                                          ({"L1C": "high"}, "L1C")])
def test_a_malformed_cn0_offset_is_one_error_naming_the_key(table, words):
    sc = _scenario({})
    sc["gnss"]["cn0_offset_db"] = table
    with pytest.raises(ScenarioError) as e:
        load(sc)
    assert "gnss.cn0_offset_db" in str(e.value) and words in str(e.value)
