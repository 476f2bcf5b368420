"""Acquisition of rising satellites (simkit/gnss/acquisition.py): closed-form first-track epochs of hand-made
visibility runs, the block split not mattering, the defaults leaving a simulated file unchanged, and a simulated
rising satellite first tracked delay_s after the mask crossing."""
from __future__ import annotations

import numpy as np
import pytest

import simkit
from simkit.errors import ScenarioError
from simkit.gnss.acquisition import Acquisition, AcquisitionConfig
from simkit.io import open_dataset, read_gnss

T = np.arange(20) * 10.0


def _vis():
    v = np.zeros((20, 1, 4), bool)
    v[:, 0, 0] = True                 # up from the start: tracked from t = 0
    v[5:, 0, 1] = True                # rises at t = 50
    v[2:8, 0, 2] = True               # rises at 20, lost at 80, back at 120
    v[12:, 0, 2] = True
    v[18:, 0, 3] = True               # rises at 180
    return v


def test_first_tracked_epochs_follow_the_delay_in_closed_form():
    acq = Acquisition(AcquisitionConfig(delay_s=25.0), 1, 4)
    out = acq.apply(T, _vis(), np.full((20, 1, 4), 0.5))
    first = [int(np.argmax(out[:, 0, s])) if out[:, 0, s].any() else None for s in range(4)]
    assert first == [0, 8, 5, None]           # 50 + 30 >= 50 + 25; 20 + 30; 180 + 10 < 180 + 25
    # satellite 2, lost at 80 and back at 120, is reacquired 30 s later (the first epoch >= 25 s)
    assert np.flatnonzero(out[:, 0, 2]).tolist() == [5, 6, 7, 15, 16, 17, 18, 19]
    assert not (out & ~_vis()).any()


def test_the_elevation_threshold_holds_a_rising_satellite_back_but_not_a_setting_one():
    el = np.tile(np.radians(np.linspace(2.0, 40.0, 20))[:, None, None], (1, 1, 4))
    el[:, 0, 0] = np.radians(np.linspace(20.0, 1.0, 20))        # setting: tracked to the end
    acq = Acquisition(AcquisitionConfig(elevation_rad=np.radians(15.0)), 1, 4)
    out = acq.apply(T, _vis(), el)
    assert out[:, 0, 0].all()
    k = int(np.argmax(out[:, 0, 1]))
    assert np.degrees(el[k, 0, 1]) >= 15.0 > np.degrees(el[k - 1, 0, 1])


def test_blocks_do_not_matter():
    vis, el = _vis(), np.full((20, 1, 4), 0.5)
    whole = Acquisition(AcquisitionConfig(delay_s=25.0), 1, 4).apply(T, vis, el)
    acq = Acquisition(AcquisitionConfig(delay_s=25.0), 1, 4)
    parts = [acq.apply(T[a:b], vis[a:b], el[a:b]) for a, b in ((0, 3), (3, 9), (9, 13), (13, 20))]
    assert np.array_equal(whole, np.concatenate(parts))


def test_the_default_is_the_identity():
    vis = _vis()
    assert Acquisition(AcquisitionConfig(), 1, 4).apply(T, vis, np.zeros(vis.shape)) is vis


def _scenario(acquisition=None):
    from pathlib import Path
    nav = Path(__file__).parents[1] / "simkit" / "data" / "KMS300DNK_R_20221591000_01H_MN.rnx.gz"
    gnss = {"rate_hz": 1 / 30, "elevation_mask_deg": 10.0, "signals": ["L1C", "B1I"],
            "constellation": [{"source": str(nav)}], "antenna": [{"lever_arm_m": [0, 0, 0]}]}
    if acquisition is not None:
        gnss["acquisition"] = acquisition
    return {"scenario": {"name": "acq", "start": "2022-06-08T10:00:00Z", "duration_s": 3000.0, "seed": 2},
            "trajectory": {"rate_hz": 1 / 30, "origin": {"lat_deg": 55.63, "lon_deg": 12.51, "height_m": 100.0},
                           "initial": {"speed_m_per_s": 0.0, "heading_deg": 0.0},
                           "segment": [{"kind": "static", "duration_s": 3000.0}]},
            "gnss": gnss}


@pytest.mark.slow
def test_a_simulated_rising_satellite_is_first_tracked_delay_after_the_mask(tmp_path):
    base = simkit.run(_scenario(), out=tmp_path / "a.h5")
    late = simkit.run(_scenario({"delay_s": 120.0}), out=tmp_path / "b.h5")
    with open_dataset(base) as d0, open_dataset(late) as d1:
        g0 = read_gnss(d0, antennas=0, obs=("code",), truth=("elevation",))
        g1 = read_gnss(d1, antennas=0, obs=("code",))
    on0, on1 = np.isfinite(g0.obs["code"]["L1C"]), np.isfinite(g1.obs["code"]["L1C"])
    rising = [s for s in range(on0.shape[1]) if not on0[0, s] and on0[:-5].any(axis=0)[s]]
    assert rising, "the hour should see a satellite rise"
    for s in rising:
        k0 = int(np.argmax(on0[:, s]))
        assert not on1[k0:k0 + 4, s].any() and on1[k0 + 4, s]      # 120 s = 4 epochs of 30 s
    # nothing else moves: the satellites up from the start have identical observables (a late-acquired one's
    # multipath process starts at its first tracked epoch)
    both = on0 & on1
    both[:, rising] = False
    assert both.sum() > 100
    assert np.array_equal(g0.obs["code"]["L1C"][both], g1.obs["code"]["L1C"][both])
    assert np.array_equal(on0[0], on1[0])


def test_bad_keys_are_named():
    with pytest.raises(ScenarioError, match="delay_s"):
        simkit.run(_scenario({"delay_s": -1.0}), out=None)


def test_the_twin_fit_reads_the_delay_of_rising_satellites_in_closed_form():
    from simkit.realdata import acquisition as fit_acq

    t = np.arange(20) * 30.0
    el = np.tile(np.radians(np.linspace(0.0, 19.0, 20))[:, None], (1, 4))
    twin_on = _vis()[:, 0, :]                    # in view: 0 from the start, 1 at 150 s, 2 at 60 s and 360 s, 3 at 540 s
    real_on = twin_on.copy()
    real_on[5:7, 1] = False                      # first tracked 60 s after it came into view
    real_on[2:4, 2] = False                      # 60 s
    real_on[12:13, 2] = False                    # 30 s after its second rise
    real_on[18:, 3] = False                      # never
    r = fit_acq.fit(t, el, np.zeros_like(el), twin_on, real_on, 0.0)
    assert [(x["column"], x["delay_s"]) for x in r["rising"]] == [(2, 60.0), (1, 60.0), (2, 30.0), (3, None)]
    assert r["delay_s"] == 60.0 and r["used"] == 3 and r["untracked"] == 1
    assert r["rising"][1]["elevation_deg"] == pytest.approx(7.0)
    assert r["agreement_with"] > r["agreement_without"]
