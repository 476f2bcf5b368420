"""The street-shadowing channel ([gnss.shadowing], simkit/gnss/shadowing.py) against closed forms: the matrix
exponential (scipy's expm as the authority), the stationary state probabilities, the mean dwell times of a
geometric run, the log-normal attenuation and its Gauss-Markov correlation; determinism, block independence, the
noise it drives, blockage and reacquisition in a simulated file; malformed tables."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

import simkit
from simkit.errors import ScenarioError
from simkit.gnss import noise, signals as sigmod
from simkit.gnss.shadowing import (BLOCKED, LOS, NOT_EVALUATED, SHADOWED, Shadowing, ShadowingConfig, fluxes,
                                   generator, transition)
from simkit.io import open_dataset, read_gnss
from simkit.pipeline import run

PI = np.array([[0.5, 0.3, 0.2], [0.6, 0.25, 0.15]])
DWELL = (12.0, 5.0, 8.0)


def _cfg(unit="s", corr=4.0, pi=PI, dwell=DWELL):
    return ShadowingConfig(elevation_edges_rad=tuple(np.radians([0.0, 30.0][:len(pi)])),
                           probabilities=tuple(np.ravel(pi)), dwell=dwell, unit=unit, attenuation_mean_db=8.0,
                           attenuation_sigma_db=3.0, attenuation_correlation=corr)


def _run(cfg, n_chains=300, m=3000, el_deg=10.0, blocks=None, speed=None, seed=5):
    sh = Shadowing(cfg, seed, [f"G{k:03d}" for k in range(n_chains)], 1, 1.0)
    el = np.full((m, n_chains), np.radians(el_deg))
    speed = np.zeros(m) if speed is None else speed
    out, k0 = [], 0
    for b in blocks or (m,):
        blk = sh.advance(k0, el[k0:k0 + b], np.ones((b, n_chains), bool), speed[k0:k0 + b], np.arange(n_chains))
        out.append(blk)
        k0 += b
    return (np.concatenate([o.state[:, 0] for o in out]), np.concatenate([o.attenuation_db[:, 0] for o in out]))


def _runs(states, value):
    """Lengths of the complete runs of ``value`` (not touching either end) in each column."""
    lengths = []
    for col in states.T:
        on = np.concatenate([[False], col == value, [False]])
        d = np.diff(on.astype(int))
        starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
        keep = (starts > 0) & (ends < col.size)
        lengths.append(ends[keep] - starts[keep])
    return np.concatenate(lengths)


def test_the_step_is_the_matrix_exponential_of_the_generator_with_the_stationary_distribution():
    for pi in PI:
        q = generator(pi, DWELL)
        assert np.allclose(q.sum(axis=1), 0.0)
        assert np.allclose(pi @ q, 0.0, atol=1e-12)                      # pi stationary
        assert np.allclose(-np.diag(q), 1.0 / np.array(DWELL))           # triangle holds: exit rates 1 / D
        for step in (0.1, 1.0, 7.0):
            p = transition(pi, DWELL, step)
            assert np.allclose(p, expm(q * step), atol=1e-12)
            assert np.allclose(pi @ p, pi, atol=1e-12)
    # fluxes that do not form a triangle: the dominant state dwells longer, the others keep their dwell
    pi, dwell = np.array([0.9, 0.05, 0.05]), (1.0, 5.0, 5.0)
    f = fluxes(pi, dwell)
    assert np.allclose(f, f.T) and f[1, 2] == 0.0
    q = generator(pi, dwell)
    assert np.allclose(pi @ q, 0.0, atol=1e-12)
    assert np.allclose(-np.diag(q)[1:], 0.2) and -q[0, 0] < 1.0


def test_state_probabilities_dwell_times_and_attenuation_match_their_closed_forms():
    state, att = _run(_cfg())
    # stationary probabilities of the bin (10 deg: the first); 300 chains x 3000 epochs, runs of 5-12 epochs:
    # about 30 000 independent runs, so the shares are good to a few 0.001
    share = np.array([(state == s).mean() for s in (LOS, SHADOWED, BLOCKED)])
    assert np.allclose(share, PI[0], atol=0.01)
    # mean run in epochs of the discrete chain: 1 / (1 - P_ii) (geometric), P = expm(Q dt)
    p = transition(PI[0], DWELL, 1.0)
    for s in (LOS, SHADOWED, BLOCKED):
        runs = _runs(state, s)
        expect = 1.0 / (1.0 - p[s, s])
        assert abs(runs.mean() / expect - 1.0) < 4.0 * runs.std() / np.sqrt(runs.size) / expect + 0.005
        # near D: a sampled exponential run is about D + dt/2, and a state left and re-entered within one step
        # counts as staying
        assert 0.0 < expect - DWELL[s] < 1.5
    # attenuation: N(8, 3^2) dB in the shadowed state (log-normal power), 0 elsewhere; lag-one correlation of the
    # unit process exp(-dt / tau)
    a = att[state == SHADOWED]
    assert abs(a.mean() - 8.0) < 0.1 and abs(a.std() - 3.0) < 0.1
    assert np.all(att[state != SHADOWED] == 0.0)
    both = (state[1:] == SHADOWED) & (state[:-1] == SHADOWED)
    x0, x1 = (att[:-1][both] - 8.0) / 3.0, (att[1:][both] - 8.0) / 3.0
    assert abs(np.mean(x0 * x1) / np.sqrt(np.mean(x0**2) * np.mean(x1**2)) - np.exp(-1.0 / 4.0)) < 0.02


def test_the_elevation_bins_select_their_probabilities():
    state, _ = _run(_cfg(), n_chains=200, m=2000, el_deg=45.0)
    share = np.array([(state == s).mean() for s in (LOS, SHADOWED, BLOCKED)])
    assert np.allclose(share, PI[1], atol=0.012)


def test_a_system_table_overrides_the_shared_probabilities():
    own = np.array([[0.8, 0.1, 0.1], [0.8, 0.1, 0.1]])
    cfg = ShadowingConfig(**{**_cfg().__dict__, "systems": (("R", tuple(own.ravel())),)})
    ids = [f"G{k:03d}" for k in range(150)] + [f"R{k:03d}" for k in range(150)]
    sh = Shadowing(cfg, 5, ids, 1, 1.0)
    el = np.full((2000, 300), np.radians(10.0))
    st = sh.advance(0, el, np.ones(el.shape, bool), np.zeros(2000), np.arange(300)).state[:, 0]
    for cols, pi in ((slice(0, 150), PI[0]), (slice(150, 300), own[0])):
        share = np.array([(st[:, cols] == s).mean() for s in (LOS, SHADOWED, BLOCKED)])
        assert np.allclose(share, pi, atol=0.015)
    # the GPS chains are the ones without the GLONASS table (their streams are keyed by satellite)
    plain = Shadowing(_cfg(), 5, ids, 1, 1.0).advance(0, el, np.ones(el.shape, bool), np.zeros(2000), np.arange(300))
    assert np.array_equal(plain.state[:, 0, :150], st[:, :150])


def test_dwell_in_metres_runs_with_the_distance_travelled():
    speed = np.full(2000, 2.0)
    metres, _ = _run(_cfg("m", corr=8.0, dwell=tuple(2 * d for d in DWELL)), n_chains=50, m=2000, speed=speed)
    seconds, _ = _run(_cfg("s"), n_chains=50, m=2000)
    assert np.array_equal(metres, seconds)      # D metres at 2 m/s: the same chain as D/2 seconds
    still, _ = _run(_cfg("m"), n_chains=50, m=200)
    assert np.all(still == still[0])            # a car that does not move keeps its state


def test_blocks_and_other_satellites_do_not_matter():
    s1, a1 = _run(_cfg(), n_chains=20, m=600)
    s2, a2 = _run(_cfg(), n_chains=20, m=600, blocks=(1, 99, 250, 250))
    assert np.array_equal(s1, s2) and np.array_equal(a1, a2)
    # a chain below the horizon for a while restarts from its bin's distribution, in the same way whatever the
    # blocks, and its stream is keyed by its satellite alone
    sh = Shadowing(_cfg(), 5, [f"G{k:03d}" for k in range(20)], 1, 1.0)
    el = np.full((600, 3), np.radians(10.0))
    present = np.ones((600, 3), bool)
    present[100:200, 1] = False
    blk = sh.advance(0, el, present, np.zeros(600), np.array([0, 5, 7]))
    assert np.all(blk.state[100:200, 0, 1] == NOT_EVALUATED)
    assert np.array_equal(blk.state[:, 0, 0], s1[:, 0]) and np.array_equal(blk.state[:, 0, 2], s1[:, 7])
    assert np.array_equal(blk.state[:100, 0, 1], s1[:100, 5])


def _scenario(shadowing=None, acquisition=None, duration=240.0):
    nav = Path(__file__).parents[1] / "simkit" / "data" / "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"
    gnss = {"rate_hz": 1.0, "elevation_mask_deg": 10.0, "signals": ["L1C", "B1I"],
            "constellation": [{"source": str(nav)}], "antenna": [{"lever_arm_m": [0, 0, 0]}, {"lever_arm_m": [1, 0, 0]}]}
    if shadowing is not None:
        gnss["shadowing"] = shadowing
    if acquisition is not None:
        gnss["acquisition"] = acquisition
    return {"scenario": {"name": "shadow", "start": "2026-04-27T06:00:00Z", "duration_s": duration, "seed": 3},
            "trajectory": {"rate_hz": 5.0, "origin": {"lat_deg": 34.2, "lon_deg": 108.9, "height_m": 400.0},
                           "initial": {"speed_m_per_s": 10.0, "heading_deg": 45.0},
                           "segment": [{"kind": "cruise", "duration_s": duration}]},
            "gnss": gnss}


SHADOW = {"elevation_deg": [0.0, 30.0, 60.0], "shadowed_probability": [0.4, 0.3, 0.1],
          "blocked_probability": [0.3, 0.1, 0.0], "dwell_s": [10.0, 5.0, 8.0], "attenuation_mean_db": 8.0,
          "attenuation_sigma_db": 3.0, "attenuation_correlation_s": 3.0}


def _read(path):
    with open_dataset(path) as ds:
        return read_gnss(ds, obs=("code", "cn0"), truth=("shadow_state", "shadow_attenuation", "elevation",
                                                         *(f"{s}/{k}" for s in ("L1C", "B1I")
                                                           for k in ("noise_code", "sigma_code", "sigma_carrier"))))


def test_a_simulated_file_stores_the_channel_and_the_noise_follows_it(tmp_path):
    plain = _read(simkit.run(_scenario(), out=tmp_path / "plain.h5"))
    a = simkit.run(_scenario(SHADOW), out=tmp_path / "a.h5")
    b = run(_scenario(SHADOW), out=tmp_path / "b.h5", block_samples=37)
    g, h = _read(a), _read(b)
    st = g.truth["shadow_state"]
    assert np.array_equal(st, h.truth["shadow_state"])                       # deterministic, block-independent
    assert np.array_equal(g.truth["shadow_attenuation"], h.truth["shadow_attenuation"], equal_nan=True)
    # (the geometry itself differs by rounding, 1e-14 dB-Hz, between block splits)
    assert np.allclose(g.obs["cn0"]["L1C"], h.obs["cn0"]["L1C"], atol=1e-9, rtol=0.0, equal_nan=True)
    assert np.array_equal(st[:, 0], st[:, 1])                                # antennas share the street
    assert {LOS, SHADOWED, BLOCKED} <= set(np.unique(st))
    for sig in ("L1C", "B1I"):
        cn0, cn0_plain = g.obs["cn0"][sig], plain.obs["cn0"][sig]
        assert not np.isfinite(g.obs["code"][sig][st == BLOCKED]).any()       # a blocked signal is not tracked
        both = np.isfinite(cn0) & np.isfinite(cn0_plain)
        assert np.allclose((cn0_plain - cn0)[both], g.truth["shadow_attenuation"][both], atol=1e-9)
        # the thermal sigmas are the DLL / PLL jitter of the lowered C/N0 (gnss.noise defaults)
        s = sigmod.get(sig)
        on = np.isfinite(cn0)
        assert np.allclose(g.truth[f"{sig}/sigma_code"][on],
                           noise.dll_sigma_m(cn0[on], s.chip_length_m, 1.0, 0.5, 0.02), rtol=1e-9)
        assert np.allclose(g.truth[f"{sig}/sigma_carrier"][on],
                           noise.pll_sigma_m(cn0[on], s.wavelength_m, 15.0, 0.02), rtol=1e-9)
        # the other streams do not move: the unit code noise of a satellite-epoch tracked in both files is the same
        unit = g.truth[f"{sig}/noise_code"] / g.truth[f"{sig}/sigma_code"]
        unit0 = plain.truth[f"{sig}/noise_code"] / plain.truth[f"{sig}/sigma_code"]
        assert np.allclose(unit[both], unit0[both], rtol=1e-9)


def test_reacquisition_after_a_blockage_follows_the_acquisition_delay(tmp_path):
    g = _read(simkit.run(_scenario(SHADOW, {"delay_s": 3.0}), out=tmp_path / "acq.h5"))
    st, on = g.truth["shadow_state"][:, 0], np.isfinite(g.obs["code"]["L1C"][:, 0])
    el = np.degrees(np.nan_to_num(g.truth["elevation"][:, 0], nan=-90.0))
    gps = np.array([str(x).startswith("G") for x in g.sat_id])
    ends = 0
    for k, s in zip(*np.nonzero((st[:-4] == BLOCKED) & gps)):
        nxt = st[k + 1:k + 5, s]
        if (nxt == BLOCKED).any() or (nxt == NOT_EVALUATED).any() or el[k + 1:k + 5, s].min() < 10.5:
            continue
        assert not on[k + 1:k + 4, s].any() and on[k + 4, s]      # a new visible run: tracked 3 s (epochs) later
        ends += 1
    assert ends >= 5


@pytest.mark.parametrize("bad, key", [
    ({"elevation_deg": [30.0, 10.0]}, "elevation_deg"),
    ({"shadowed_probability": [0.4, 0.3]}, "shadowed_probability"),
    ({"blocked_probability": [0.7, 0.1, 0.0]}, "blocked_probability"),
    ({"dwell_s": [10.0, 0.0, 8.0]}, "dwell_s"),
    ({"dwell_m": [10.0, 5.0, 8.0]}, "dwell_s"),
    ({"attenuation_correlation_m": 3.0}, "attenuation_correlation_m"),
    ({"antennas": "each"}, "antennas"),
    ({"attenuation_mean_db": -1.0}, "attenuation_mean_db"),
    ({"dwel_s": 1.0}, "dwel_s"),
    ({"systems": {"X": {"shadowed_probability": [0.1] * 3, "blocked_probability": [0.1] * 3}}}, "systems.X"),
    ({"systems": {"R": {"shadowed_probability": [0.1] * 3}}}, r"systems\.R\.blocked_probability"),
])
def test_a_malformed_table_is_one_error_naming_its_key(bad, key):
    with pytest.raises(ScenarioError, match=rf"gnss\.shadowing\.{key}"):
        simkit.run(_scenario({**SHADOW, **bad}), out=None)
