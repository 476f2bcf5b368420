"""The horizon profile of a station (simkit/realdata/horizon.py): recovered from tracking decided by a known
profile, and honoured by the simulator exactly as inferred (a static level antenna facing north)."""
from __future__ import annotations

import numpy as np
import pytest

from simkit.realdata import horizon


def _true_mask_deg(az_deg):
    """A step horizon: 8 deg between azimuths 40 and 90 (a building), 3 deg between 200 and 260, else 0."""
    return np.where((az_deg >= 40) & (az_deg < 90), 8.0, np.where((az_deg >= 200) & (az_deg < 260), 3.0, 0.0))


def test_profile_recovers_a_step_horizon_and_classifies_every_satellite_epoch():
    rng = np.random.default_rng(3)
    az = rng.uniform(0, 2 * np.pi, 20000)
    el = np.radians(rng.uniform(0, 20, 20000))
    on = np.degrees(el) >= _true_mask_deg(np.degrees(az))
    prof = np.degrees(horizon.profile(el, az, on, 0.0))
    assert prof.shape == (36,)
    sector = np.arange(36) * 10 + 5
    # each sector's threshold lies between its highest untracked and its lowest tracked elevation
    for k, truth in enumerate(_true_mask_deg(sector)):
        sel = (np.degrees(az) // 10).astype(int) == k
        e = np.degrees(el[sel])
        assert (e[~on[sel]].max() if (~on[sel]).any() else 0.0) <= prof[k] <= e[on[sel]].min() + 1e-9
        assert prof[k] == pytest.approx(truth, abs=0.2)
    table = horizon.mask_table(np.radians(prof))
    inner = np.abs(np.degrees(az) - 10 * np.round(np.degrees(az) / 10)) > 0.02   # off the 0.02 deg joins
    assert np.array_equal(horizon.below(el, az, table)[inner], ~on[inner])
    agree = horizon.agreement(el[None], az[None], on[None], np.ones((1, 20000), bool), 0.0, table)["agreement"]
    assert agree > 1 - (~inner).sum() / inner.size


def test_profile_ignores_what_the_twin_does_not_simulate_and_takes_the_floor_in_empty_sectors():
    az = np.radians([15.0, 15.0, 15.0, 15.0])
    el = np.radians([1.0, 2.0, 3.0, 9.0])
    on = np.array([False, False, True, True])
    assert np.degrees(horizon.profile(el, az, on, 0.0)[1]) == pytest.approx(2.5)
    # the two untracked satellite-epochs are not simulated either: they say nothing about the horizon
    sim = np.array([False, False, True, True])
    assert horizon.profile(el, az, on, 0.0, simulated=sim)[1] == 0.0
    assert np.all(horizon.profile(el, az, on, np.radians(0.5))[np.arange(36) != 1] == np.radians(0.5))


def test_holdout_fits_on_one_half_and_checks_on_the_other():
    m = 10
    el = np.radians(np.tile([[1.0, 6.0]], (m, 1)))
    az = np.radians(np.tile([[45.0, 45.0]], (m, 1)))
    real_on = np.zeros((m, 2), bool)
    real_on[:, 1] = True
    real_on[m // 2:, 0] = True            # the low satellite is tracked in the second half only
    twin_on = np.ones((m, 2), bool)
    h = horizon.holdout(el, az, real_on, twin_on, 0.0)
    # fitted on the first half the sector masks 1 deg: wrong for the 5 second-half epochs of the low satellite
    assert h["first->second"] == {"agreement": 0.5, "satellite_epochs": 10, "real_not_twin": 5, "twin_not_real": 0}
    assert h["second->first"] == {"agreement": 0.5, "satellite_epochs": 10, "real_not_twin": 0, "twin_not_real": 5}


def test_the_simulator_masks_exactly_what_the_profile_says(tmp_path):
    """A static twin-like scenario with the profile as [[environment.body_mask]]: the file tracks a satellite-epoch
    if and only if it is above the elevation floor and not below the profile (horizon.below)."""
    from simkit.constellation.geometry import angles_from_enu, lines_of_sight_enu
    from simkit.io import open_dataset, read_gnss
    from simkit.pipeline import run
    from simkit.realdata import fidelity

    table = horizon.mask_table(np.radians(_true_mask_deg(np.arange(36) * 10 + 5) * 2.0))
    ref_lla = (55.0, 12.5, 50.0)
    sc = {"scenario": {"name": "h", "start": "2022-06-08T10:00:00Z", "duration_s": 3000.0, "seed": 1},
          "trajectory": {"rate_hz": 1 / 60, "origin": dict(zip(("lat_deg", "lon_deg", "height_m"), ref_lla)),
                         "initial": {"speed_m_per_s": 0.0, "heading_deg": 0.0},
                         "segment": [{"kind": "static", "duration_s": 3000.0}]},
          "gnss": {"rate_hz": 1 / 60, "elevation_mask_deg": 0.0, "signals": ["L1C", "B1I"],
                   "constellation": [{"source": "nominal:gps"}, {"source": "nominal:bds"}],
                   "antenna": [{"lever_arm_m": [0.0, 0.0, 0.0]}]},
          "environment": {"reflections": False, "body_mask": [table]}}
    path = run(sc, out=tmp_path / "h.h5")
    with open_dataset(path) as ds:
        g = read_gnss(ds, antennas=0, obs=("code", "carrier"))
    import pymap3d

    rx = np.array(pymap3d.geodetic2ecef(*ref_lla))
    el, az = angles_from_enu(lines_of_sight_enu(np.broadcast_to(rx, (g.t.size, 3)), g.sat_pos_ecef)[0])
    on = fidelity.tracked(g.obs)
    expected = (el >= 0.0) & ~horizon.below(el, az, table)
    assert on.sum() > 100 and (expected & (el < np.radians(16))).sum() > 5
    far = np.abs(el - np.radians(np.interp(np.degrees(az), table["azimuth_deg"], table["elevation_deg"],
                                           period=360))) > np.radians(0.05)
    assert np.array_equal(on[far], expected[far])
