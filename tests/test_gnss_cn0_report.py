"""The receiver's reported C/N0 ([gnss.cn0_report], simkit/gnss/cn0_report.py): the estimate's noise against its
closed form (Sheppard's correction for the rounding), the output step, the other terms' draws untouched,
determinism and block independence, malformed tables; and the step read from real receivers' files (the RINEX
values themselves are the authority: whole dB-Hz from the u-blox receivers of the Berlin and Hong Kong drives,
tenths from the solo0150 station)."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from realdata_helpers import BERLIN_OBS, OBS
from simkit.cli import main
from simkit.errors import ScenarioError
from simkit.io import open_dataset, read_gnss
from simkit.pipeline import run
from simkit.realdata.noise_fit import cn0_resolution

SIGNALS = ("L1C", "B1I")


def _scenario(report=None, duration=600.0, seed=3):
    nav = Path(__file__).parents[1] / "simkit" / "data" / "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"
    gnss = {"rate_hz": 1.0, "elevation_mask_deg": 5.0, "signals": list(SIGNALS),
            "constellation": [{"source": str(nav)}], "antenna": [{"lever_arm_m": [0, 0, 0]}, {"lever_arm_m": [1, 0, 0]}]}
    if report is not None:
        gnss["cn0_report"] = report
    return {"scenario": {"name": "cn0", "start": "2026-04-27T06:00:00Z", "duration_s": duration, "seed": seed},
            "trajectory": {"rate_hz": 1.0, "origin": {"lat_deg": 34.2, "lon_deg": 108.9, "height_m": 400.0},
                           "initial": {"speed_m_per_s": 0.0, "heading_deg": 0.0},
                           "segment": [{"kind": "static", "duration_s": duration}]},
            "gnss": gnss}


def _read(path, truth=True):
    with open_dataset(path) as ds:
        return read_gnss(ds, obs=("code", "carrier", "doppler", "cn0"),
                         truth=tuple(f"{s}/cn0" for s in SIGNALS) if truth else ())


@pytest.fixture(scope="module")
def plain(tmp_path_factory):
    return _read(run(_scenario(), out=tmp_path_factory.mktemp("plain") / "p.h5"), truth=False)


def test_without_the_table_the_file_is_as_before(tmp_path):
    path = run(_scenario(), out=tmp_path / "p.h5")
    with h5py.File(path) as f:
        assert not any(f"gnss/truth/{s}/cn0" in f for s in SIGNALS)


def test_noise_and_step_against_the_closed_form(tmp_path, plain):
    """reported - true C/N0 has variance sigma^2 + q^2 / 12 (white noise, then rounding to q: Sheppard), zero
    mean; every value is a multiple of q; the true C/N0 is the C/N0 of the run without the table, and code,
    carrier and Doppler are unchanged (their draws come from other streams)."""
    sigma, q = 0.8, 0.25
    g = _read(run(_scenario({"sigma_db": sigma, "resolution_dbhz": q}), out=tmp_path / "r.h5"))
    for s in SIGNALS:
        rep, true = g.obs["cn0"][s], g.truth[f"{s}/cn0"]
        ok = np.isfinite(rep)
        assert ok.sum() > 5000
        np.testing.assert_array_equal(np.isfinite(true), ok)
        np.testing.assert_array_equal(true, plain.obs["cn0"][s])
        err = (rep - true)[ok]
        n = err.size
        var = sigma ** 2 + q ** 2 / 12
        assert err.var() == pytest.approx(var, rel=4 * np.sqrt(2 / n))
        assert abs(err.mean()) < 4 * np.sqrt(var / n)
        np.testing.assert_allclose(rep[ok] / q, np.round(rep[ok] / q), atol=1e-9)
        for k in ("code", "carrier", "doppler"):
            np.testing.assert_array_equal(g.obs[k][s], plain.obs[k][s])


def test_the_step_alone_rounds_to_the_nearest_multiple(tmp_path):
    g = _read(run(_scenario({"resolution_dbhz": 1.0}), out=tmp_path / "r.h5"))
    for s in SIGNALS:
        rep, true = g.obs["cn0"][s], g.truth[f"{s}/cn0"]
        ok = np.isfinite(rep)
        np.testing.assert_array_equal(rep[ok], np.round(true[ok]))
        assert np.abs(rep - true)[ok].max() <= 0.5


def test_same_seed_same_draws_whatever_the_blocks(tmp_path):
    sc = _scenario({"sigma_db": 1.0}, duration=300.0)
    a = _read(run(sc, out=tmp_path / "a.h5"))
    b = _read(run(sc, out=tmp_path / "b.h5", block_samples=37))
    c = _read(run(_scenario({"sigma_db": 1.0}, duration=300.0, seed=4), out=tmp_path / "c.h5"))
    for s in SIGNALS:
        np.testing.assert_array_equal(a.obs["cn0"][s], b.obs["cn0"][s])
        both = np.isfinite(a.obs["cn0"][s]) & np.isfinite(c.obs["cn0"][s])
        assert not np.array_equal(a.obs["cn0"][s][both], c.obs["cn0"][s][both])


@pytest.mark.parametrize("table, key", [({"sigma_db": -1.0}, "gnss.cn0_report.sigma_db"),
                                        ({"resolution_dbhz": -0.5}, "gnss.cn0_report.resolution_dbhz"),
                                        ({"sigma_db": "big"}, "gnss.cn0_report.sigma_db"),
                                        ({"sigma_db": 1.0, "step": 1.0}, "gnss.cn0_report.step"),
                                        ({"resolution": 1.0}, "gnss.cn0_report.resolution")])
def test_a_bad_table_is_one_error_naming_its_key(tmp_path, table, key):
    with pytest.raises(ScenarioError, match=key.replace(".", r"\.")):
        run(_scenario(table), out=tmp_path / "bad.h5")
    assert not list(tmp_path.iterdir())


def _imported(tmp_path, name):
    out = tmp_path / (Path(name).stem + ".h5")
    assert main(["import", str(OBS / name), "-o", str(out), "-q"]) == 0
    with open_dataset(out) as ds:
        return read_gnss(ds, obs=("cn0",)).obs["cn0"]


@pytest.mark.parametrize("name, step", [(BERLIN_OBS.name, 1.0), ("UrbanNav-HK-Medium-Urban-1_30ep.obs", 1.0),
                                        ("solo0150.16o", 0.1)])
def test_the_output_step_of_real_receivers(tmp_path, name, step):
    cn0 = _imported(tmp_path, name)
    assert cn0_resolution(cn0.values()) == step


def test_a_continuous_or_empty_series_has_no_step(plain):
    assert cn0_resolution(plain.obs["cn0"].values()) == 0.0            # simkit's own C/N0 is continuous
    assert cn0_resolution([np.full((5, 3), np.nan)]) == 0.0
    assert cn0_resolution([np.full((20, 3), 40.0)]) == 0.0             # constant: nothing to tell
