"""simkit twin --fit's street-shadowing channel (simkit/realdata/shadowing_fit.py) recovers the parameters of a file
simulated with known ones ([gnss.shadowing]), its C/N0 given a receiver's estimation noise of 1 dB."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from simkit.gnss import signals as sigmod
from simkit.gnss.shadowing import NOT_EVALUATED, transition
from simkit.io import open_dataset, read_gnss
from simkit.pipeline import run
from simkit.realdata import shadowing_fit

TRUE = {"elevation_deg": [0.0, 30.0, 60.0], "shadowed_probability": [0.4, 0.3, 0.25],
        "blocked_probability": [0.3, 0.15, 0.15], "dwell_s": [20.0, 10.0, 10.0], "attenuation_mean_db": 9.0,
        "attenuation_sigma_db": 3.0, "attenuation_correlation_s": 5.0}
MASK = 10.0


def _scenario(duration=1800.0):
    nav = Path(__file__).parents[1] / "simkit" / "data" / "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"
    return {"scenario": {"name": "fit", "start": "2026-04-27T06:00:00Z", "duration_s": duration, "seed": 11},
            "trajectory": {"rate_hz": 1.0, "origin": {"lat_deg": 34.2, "lon_deg": 108.9, "height_m": 400.0},
                           "initial": {"speed_m_per_s": 0.0, "heading_deg": 0.0},
                           "segment": [{"kind": "static", "duration_s": duration}]},
            "gnss": {"rate_hz": 1.0, "elevation_mask_deg": MASK, "signals": ["L1C", "B1I"],
                     "constellation": [{"source": str(nav)}], "antenna": [{"lever_arm_m": [0, 0, 0]}],
                     "shadowing": TRUE}}


def test_the_fit_recovers_the_channel_of_a_simulated_file(tmp_path):
    path = run(_scenario(), out=tmp_path / "sim.h5")
    with open_dataset(path) as ds:
        g = read_gnss(ds, antennas=0, obs=("cn0",), truth=("shadow_state", "elevation"))
    el, state = g.truth["elevation"], g.truth["shadow_state"]
    above = (state != NOT_EVALUATED) & (np.degrees(np.nan_to_num(el, nan=-90.0)) >= MASK)
    noise = np.random.default_rng(0)
    cn0 = {s: g.obs["cn0"][s] + noise.normal(0.0, 1.0, el.shape) for s in g.signals}
    offsets = {s: sigmod.get(s).cn0_offset_db for s in g.signals}
    out = shadowing_fit.fit(cn0, offsets, el, above, 1.0, systems=[str(x)[0] for x in g.sat_id])
    c = out["config"]
    # both systems were simulated with the one table: each system's own fit is near the pooled one
    assert set(c["systems"]) == {"G", "C"}
    for table in c["systems"].values():
        for key in ("shadowed_probability", "blocked_probability"):
            assert np.allclose(table[key][1:7], c[key][1:7], atol=0.08)
    # state shares per 10-degree bin against the true ones of the bin that holds it (bins with data)
    n = np.bincount(np.clip((np.degrees(el[above]) // 10).astype(int), 0, 8), minlength=9)
    checked = 0
    for k in range(1, 9):
        if n[k] < 2000:
            continue
        true_bin = np.searchsorted(TRUE["elevation_deg"], 10.0 * k, side="right") - 1
        assert abs(c["shadowed_probability"][k] - TRUE["shadowed_probability"][true_bin]) < 0.06, k
        assert abs(c["blocked_probability"][k] - TRUE["blocked_probability"][true_bin]) < 0.04, k
        checked += 1
    assert checked >= 4
    # dwell: the fit gives -dt / ln A_ii; the simulator's step keeps a state with P_ii = expm(Q dt)_ii, whose
    # -1 / ln P_ii is D within about 10 % here
    for i, d in enumerate(TRUE["dwell_s"]):
        p = transition([1 - TRUE["shadowed_probability"][1] - TRUE["blocked_probability"][1],
                        TRUE["shadowed_probability"][1], TRUE["blocked_probability"][1]], TRUE["dwell_s"], 1.0)
        assert abs(c["dwell_s"][i] / (-1.0 / np.log(p[i, i])) - 1.0) < 0.2, (i, c["dwell_s"])
    assert abs(c["attenuation_mean_db"] - 9.0) < 0.6
    # the fitted spread holds the 1 dB estimation noise too: sqrt(3^2 + 1^2) = 3.16
    assert abs(c["attenuation_sigma_db"] - np.hypot(3.0, 1.0)) < 0.4
    # lag-one correlation of attenuation plus white noise: exp(-1/5) 9 / 10, so the time comes out shorter
    rho = np.exp(-1.0 / 5.0) * 9.0 / 10.0
    assert abs(c["attenuation_correlation_s"] / (-1.0 / np.log(rho)) - 1.0) < 0.25
