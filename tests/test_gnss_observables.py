"""GNSS observables: closure on the truth terms, DD noise statistics, Doppler vs carrier, slips, blocks."""

import numpy as np
import pytest

from simkit import earth, frames
from simkit.earth import C_LIGHT
from simkit.constellation import load_sky
from simkit.errors import ScenarioError
from simkit.gnss import (GnssSimulator, dd_covariance, double_difference, parse_config, reference_satellites)
from simkit.pipeline import gnss_rows
from simkit.section import Section

from conftest import DATA

NAV = DATA / "rinex_nav" / "BRDC00WRD_U_20161580000_01D_MN.rnx"
WEEK, SOW = 1900, 86400.0 + 10 * 3600.0  # 2016-06-06 10:00 GPST, inside the file's records
ORIGIN = frames.lla_to_ecef(np.radians(34.2), np.radians(108.9), 400.0)
ALL_OFF = {k: False for k in ("receiver_clock", "satellite_clock", "group_delay", "ionosphere", "troposphere",
                              "multipath", "noise", "cycle_slips")}



def make(extra=None, duration=120.0, seed=3, start=(WEEK, SOW)):
    table = {"rate_hz": 1.0, "signals": ["L1C", "L2W", "B1I"], "constellation": [{"source": str(NAV)}],
             "antenna": [{"lever_arm_m": [0.0, 0.0, 0.0]}, {"lever_arm_m": [3.965, 0.0, 0.0]},
                         {"lever_arm_m": [0.0, 9.445, 0.2]}]}
    table.update(extra or {})
    cfg = parse_config(Section(table, "gnss"))
    return GnssSimulator(cfg, load_sky(cfg.sources), start[0], start[1], seed, duration)


def consistent_truth(pos, vel, heading_deg=30.0):
    """Level attitude at a fixed heading, with the body rate that keeps it (Earth rate + transport rate)."""
    rot = frames.attitude_from_euler(0.0, 0.0, np.radians(heading_deg))
    lla = frames.ecef_to_lla(pos)
    v_enu = frames.ecef_to_enu_vec(vel, lla[:, 0:1], lla[:, 1:2]) if vel.ndim == 1 else \
        frames.ecef_to_enu_vec(vel, lla[:, 0], lla[:, 1])
    w_in = earth.earth_rate_enu(lla[:, 0]) + earth.transport_rate_enu(lla[:, 0], lla[:, 2], v_enu)
    return pos, vel, np.tile(rot.as_quat(), (len(pos), 1)), rot.inv().apply(w_in)


def static_truth(t, heading_deg=30.0):
    m = t.size
    return consistent_truth(np.array(np.broadcast_to(ORIGIN, (m, 3))), np.zeros((m, 3)), heading_deg)


def run(sim, truth=None, blocks=1):
    t = sim.epoch_times()
    truth = truth or static_truth(t)
    parts = [sim.process(t[i], *(x[i] for x in truth)) for i in np.array_split(np.arange(t.size), blocks)]
    rows = [gnss_rows(p, prefix="") for p in parts]
    return {k: np.concatenate([r[k] for r in rows]) for k in rows[0]}


def test_observables_equal_sum_of_truth_terms():
    sim = make({"slip_rate_per_h": 20.0, "clock": "per_antenna"})
    out = run(sim)
    for j, sig in enumerate(sim.cfg.signals):
        lam = C_LIGHT / sim.signals[j].freq_hz
        clk = out["truth/receiver_clock"][..., None] + out["truth/satellite_clock"]
        gd = C_LIGHT * sim.group_delay_s[:, j]
        tr = f"truth/{sig}/"
        code = (out["truth/range"] + clk + gd + out[tr + "ionosphere"] + out["truth/troposphere"]
                + out[tr + "multipath_code"] + out[tr + "noise_code"])
        phase = (out["truth/range"] + clk - out[tr + "ionosphere"] + out["truth/troposphere"]
                 + out[tr + "multipath_carrier"] + out[tr + "noise_carrier"])
        rate = (out["truth/range_rate"] + out["truth/receiver_clock_drift"][..., None]
                + out["truth/satellite_clock_drift"] - out[tr + "ionosphere_rate"] + out["truth/troposphere_rate"])
        ok = np.isfinite(out[f"obs/{sig}/code"])
        assert ok.sum() > 300
        assert np.max(np.abs(out[f"obs/{sig}/code"] - code)[ok]) < 1e-3
        carrier_m = (out[f"obs/{sig}/carrier"] - out[f"obs/{sig}/ambiguity"]) * lam
        assert np.max(np.abs(carrier_m - phase)[ok]) < 1e-3
        dop_ms = -(out[f"obs/{sig}/doppler"] - out[tr + "noise_doppler"]) * lam
        assert np.max(np.abs(dop_ms - rate)[ok]) < 1e-3
        # every error term really is on (none of them silently zero)
        for term in ("ionosphere", "multipath_code", "noise_carrier"):
            assert np.nanstd(out[tr + term][ok]) > 0
    assert np.ptp(out["truth/receiver_clock"][:, 0] - out["truth/receiver_clock"][:, 1]) > 0  # per-antenna clocks


@pytest.mark.parametrize("model", ["constant", "cn0"])
def test_dd_carrier_residuals_have_configured_sigma(model):
    sigma = 0.003
    sim = make({"errors": {**ALL_OFF, "noise": True},
                "noise": {"model": model, "carrier_sigma_m": sigma}}, duration=600.0, seed=11)
    out = run(sim)
    sig = "L1C"
    lam = C_LIGHT / sim.signals[0].freq_hz
    carrier = out[f"obs/{sig}/carrier"]
    valid = np.isfinite(carrier).all(axis=1)
    ref = reference_satellites(out["truth/elevation"][:, 0], valid, sim.sat_ids)
    resid = (double_difference(carrier, ref) - double_difference(out["truth/range"], ref) / lam
             - double_difference(out[f"obs/{sig}/ambiguity"].astype(float), ref)) * lam
    if model == "constant":
        r = resid[np.isfinite(resid)]
        print(f"\nDD carrier residual ({r.size} values): mean {r.mean() * 1e3:+.3f} mm, std {r.std() * 1e3:.3f} mm, "
              f"configured DD sigma {2 * sigma * 1e3:.3f} mm")
        assert abs(r.std() / (2 * sigma) - 1) < 0.10
        assert abs(r.mean()) < 3 * 2 * sigma / np.sqrt(r.size) * 3  # zero mean (correlated DDs: generous)
    else:
        # whiten each epoch's DD vector with the covariance from the helper: unit variance if both are right
        z = []
        for k in range(resid.shape[0]):
            q, ant, sat = dd_covariance(out[f"truth/{sig}/sigma_carrier"][k], ref[k], valid[k])
            if len(sat) == 0:
                continue
            v = resid[k][ant - 1, sat]
            z.append(np.linalg.solve(np.linalg.cholesky(q), v))
        z = np.concatenate(z)
        print(f"\nwhitened DD carrier residuals (C/N0 noise): mean {z.mean():+.4f}, std {z.std():.4f}")
        assert abs(z.std() - 1) < 0.10 and abs(z.mean()) < 0.05


def test_doppler_matches_time_differenced_carrier_static():
    # quiet: no noise, no multipath, no slips, and an ideal oscillator (a crystal's white-FM phase noise makes
    # the time-differenced carrier differ from the Doppler by c sqrt(h0 / 2 dt), about 0.1 m/s for a TCXO)
    sim = make({"oscillator": "ideal", "errors": {**ALL_OFF, "receiver_clock": True, "satellite_clock": True,
                                                  "ionosphere": True, "troposphere": True}}, duration=300.0)
    out = run(sim)
    for j, sig in enumerate(sim.cfg.signals):
        lam = C_LIGHT / sim.signals[j].freq_hz
        phi = out[f"obs/{sig}/carrier"]
        dphi = np.diff(phi, axis=0)                                      # cycles over 1 s
        mean_dop = 0.5 * (out[f"obs/{sig}/doppler"][1:] + out[f"obs/{sig}/doppler"][:-1])
        err = (dphi + mean_dop) * lam                                    # Doppler = -d(phase)/dt
        e = err[np.isfinite(err)]
        print(f"\n{sig}: |Doppler - time-differenced carrier| max {np.abs(e).max() * 1e3:.4f} mm/s")
        assert np.abs(e).max() < 1e-3


def test_high_dynamics_doppler_tens_of_khz():
    """Straight line at 7.5 km/s, 10 Hz: Doppler of tens of kHz still equals -d(carrier)/dt."""
    quiet = {**ALL_OFF, "receiver_clock": True, "satellite_clock": True}
    sim = make({"rate_hz": 10.0, "signals": ["L1C"], "oscillator": "ideal", "errors": quiet}, duration=20.0)
    t = sim.epoch_times()
    v = np.array([5000.0, -4000.0, 3700.0])
    pos = ORIGIN + t[:, None] * v
    truth = consistent_truth(pos, np.tile(v, (t.size, 1)))
    out = run(sim, truth)
    lam = C_LIGHT / sim.signals[0].freq_hz
    dop = out["obs/L1C/doppler"]
    err = (np.diff(out["obs/L1C/carrier"], axis=0) / 0.1 + 0.5 * (dop[1:] + dop[:-1])) * lam
    e = err[np.isfinite(err)]
    print(f"\nmax |Doppler| {np.nanmax(np.abs(dop)) / 1e3:.1f} kHz; max |D - dphi/dt| {np.abs(e).max() * 1e3:.4f} mm/s")
    assert np.nanmax(np.abs(dop)) > 2e4
    assert np.abs(e).max() < 1e-3


def test_block_split_gives_identical_arrays_and_seed_determinism():
    extra = {"slip_rate_per_h": 30.0, "slip": [{"t_s": 50.0, "sat": "G01", "cycles": 7}],
             "outage": [{"start_s": 20.0, "end_s": 35.0, "antennas": [1]}]}
    a = run(make(extra), blocks=1)
    b = run(make(extra), blocks=7)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)
    c = run(make(extra, seed=4))
    assert not np.array_equal(a["obs/L1C/code"], c["obs/L1C/code"], equal_nan=True)
    # the blocks' geometry computed a block ahead on a worker thread (what simkit.run does): the same arrays
    sim = make(extra)
    t = sim.epoch_times()
    truth = static_truth(t)
    parts = list(sim.process_blocks((t[i], *(x[i] for x in truth))
                                    for i in np.array_split(np.arange(t.size), 7)))
    assert len(parts) == 7
    rows = [gnss_rows(p, prefix="") for p in parts]
    for k in a:
        np.testing.assert_array_equal(a[k], np.concatenate([r[k] for r in rows]), err_msg=k)


def test_slips_outages_and_lli():
    sim = make({"slip": [{"t_s": 50.0, "sat": "G01", "antenna": 1, "signal": "L1C", "cycles": 7}],
                "outage": [{"start_s": 20.0, "end_s": 35.0, "antennas": [2], "sats": ["G06"]}]})
    out = run(sim)
    amb, lli = out["obs/L1C/ambiguity"], out["obs/L1C/lli"]
    g01, g06 = sim.sat_ids.index("G01"), sim.sat_ids.index("G06")
    assert amb[50, 1, g01] - amb[49, 1, g01] == 7 and lli[50, 1, g01] == 1
    assert np.all(amb[50, 0, g01] == amb[49, 0, g01]) and lli[50, 0, g01] == 0
    assert np.isnan(out["obs/L1C/carrier"][20:35, 2, g06]).all() and np.isfinite(out["obs/L1C/carrier"][19, 2, g06])
    assert lli[35, 2, g06] == 1
    # the ambiguity changes only at epochs flagged by the LLI
    tracked = np.isfinite(out["obs/L1C/carrier"])
    change = (np.diff(amb, axis=0) != 0) & tracked[1:] & tracked[:-1]
    assert np.all(lli[1:][change] == 1)


def test_antenna_positions_follow_attitude_and_masking():
    sim = make({"signals": ["L1C"]}, duration=2.0)
    out = run(sim, static_truth(sim.epoch_times(), heading_deg=90.0))
    lla = frames.ecef_to_lla(ORIGIN)
    # heading 90 deg: body y (forward) points east, body x (right) points south
    expected = ORIGIN + frames.enu_to_ecef_vec(np.array([0.0, -3.965, 0.0]), lla[0], lla[1])
    np.testing.assert_allclose(out["truth/antenna_pos_ecef"][0, 1], expected, atol=1e-9)
    # an antenna pointing down (boresight -z) sees nothing above its horizon plane
    down = make({"signals": ["L1C"], "antenna": [{"lever_arm_m": [0, 0, 0], "boresight_b": [0, 0, -1]}]}, 2.0)
    assert np.isnan(run(down)["obs/L1C/code"]).all()


def test_config_errors_name_the_key():
    base = {"constellation": [{"source": "nominal:gps"}], "antenna": [{"lever_arm_m": [0, 0, 0]}]}
    with pytest.raises(ScenarioError, match=r"gnss.signals"):
        parse_config(Section({**base, "signals": ["L9X"]}, "gnss"))
    with pytest.raises(ScenarioError, match=r"gnss.antenna\[0\].lever_arm_m"):
        parse_config(Section({**base, "antenna": [{"lever_arm_m": [0, 0]}]}, "gnss"))
    with pytest.raises(ScenarioError, match=r"gnss.errors.ionosfere"):
        parse_config(Section({**base, "errors": {"ionosfere": False}}, "gnss"))
    with pytest.raises(ScenarioError, match=r"gnss.slip\[0\].cycles"):
        parse_config(Section({**base, "slip": [{"t_s": 1.0, "cycles": 0}]}, "gnss"))


def test_stored_satellite_positions_are_in_the_emission_frame_as_rtklib_expects(tmp_path):
    """/gnss/sat_pos_ecef is the position at emission in the ECEF frame of emission (RTKLIB satposs) of the
    broadcast satellite: RTKLIB's geodist (which adds the Sagnac term) on it and the true antenna positions gives the
    stored (true) range minus the stored broadcast orbit's range error < 1 mm."""
    import pyrtklib as rtk

    import simkit

    path = simkit.run("quickstart", out=tmp_path / "q.h5", overrides=["scenario.duration_s=20"])
    with simkit.open(path) as ds:
        sat, ant = ds["gnss/sat_pos_ecef"][:], ds["gnss/truth/antenna_pos_ecef"][:]
        orbit = ds["gnss/truth/orbit_range_error"][:]
        rng = ds["gnss/truth/range"][:] - orbit
        assert ds["gnss/sat_pos_ecef"].attrs["frame"] == "ECEF at emission"
    rs, rr, e = rtk.Arr1Ddouble(6), rtk.Arr1Ddouble(3), rtk.Arr1Ddouble(3)
    worst, checked = 0.0, 0
    for m in range(0, sat.shape[0], 5):
        for a in range(ant.shape[1]):
            for i in range(3):
                rr[i] = float(ant[m, a, i])
            for s in np.flatnonzero(np.isfinite(rng[m, a])):
                for i in range(3):
                    rs[i] = float(sat[m, s, i])
                worst = max(worst, abs(rtk.geodist(rs, rr, e) - rng[m, a, s]))
                checked += 1
    print(f"\nRTKLIB geodist vs stored range: max {worst * 1e3:.4f} mm over {checked} ranges")
    assert checked > 100 and worst < 1e-3
    assert np.nanstd(orbit) > 0.05  # the default truth has broadcast orbit errors (docs/truth_errors.md)


def test_noise_of_a_satellite_does_not_depend_on_the_mask_or_the_other_satellites():
    """Draws are keyed by (antenna, satellite, epoch): a higher mask, or another constellation, leaves the noise
    of every satellite tracked in both runs unchanged."""
    a = run(make({"elevation_mask_deg": 5.0}))
    b = run(make({"elevation_mask_deg": 25.0}))
    both = np.isfinite(a["obs/L1C/code"]) & np.isfinite(b["obs/L1C/code"])
    assert both.sum() > 500 and (np.isfinite(a["obs/L1C/code"]) & ~both).sum() > 100
    for term in ("noise_code", "noise_carrier", "noise_doppler"):
        np.testing.assert_array_equal(a[f"truth/L1C/{term}"][both], b[f"truth/L1C/{term}"][both], err_msg=term)


def test_static_output_carries_the_broadcast_klobuchar_coefficients_used():
    """A scenario override wins for GPS; this nav file's header has no IONOSPHERIC CORR lines, so BDS gets the
    defaults (the BDSA/BDSB lines of BRDM00DLR_S_20261170000_01D_MN.rnx); rows follow /gnss/iono_systems."""
    from simkit.gnss import atmosphere

    alpha, beta = [1.0e-8, 2.0e-8, -6.0e-8, -1.2e-7], [9.0e4, 1.0e5, -6.5e4, -5.2e5]
    st = make({"ionosphere": {"gps_alpha": alpha, "gps_beta": beta}}, duration=2.0).static()
    assert st.iono_systems.tolist() == ["G", "C"]
    np.testing.assert_array_equal(st.iono_alpha, [alpha, atmosphere.DEFAULT_BDS_ALPHA])
    np.testing.assert_array_equal(st.iono_beta, [beta, atmosphere.DEFAULT_BDS_BETA])


def test_each_signal_has_its_multipath_correlation_time():
    """[gnss.multipath.signal_correlation_time_s]: the stored carrier multipath of L2W decorrelates over its own
    5 s, L1C's and B1I's over the common 200 s (lag-one correlation of the unit process exp(-dt / tau))."""
    sim = make({"multipath": {"correlation_time_s": 200.0, "signal_correlation_time_s": {"L2W": 5.0}}},
               duration=600.0)
    out = run(sim, blocks=3)
    for sig, tau in (("L1C", 200.0), ("L2W", 5.0), ("B1I", 200.0)):
        x = out[f"truth/{sig}/multipath_carrier"]
        el = out["truth/elevation"]
        u = x / (sim.cfg.multipath.carrier_sigma_m * np.exp(-np.maximum(el, 1e-3) / sim.cfg.multipath.elevation_scale_rad))
        pair = np.isfinite(u[1:]) & np.isfinite(u[:-1])
        r = np.sum(u[1:][pair] * u[:-1][pair]) / np.sqrt(np.sum(u[1:][pair] ** 2) * np.sum(u[:-1][pair] ** 2))
        assert r == pytest.approx(np.exp(-1.0 / tau), abs=0.03), sig


@pytest.mark.parametrize("table, key, words", [({"L5Q": 3.0}, "L5Q", "unknown key"),
                                               ({"L1C": -1.0}, "L1C", "must be > 0"),
                                               ({"L1C": "long"}, "L1C", "expected")])
def test_a_bad_signal_correlation_time_is_one_error_naming_the_key(table, key, words):
    with pytest.raises(ScenarioError) as e:
        make({"multipath": {"signal_correlation_time_s": table}})
    assert f"gnss.multipath.signal_correlation_time_s.{key}" in str(e.value) and words in str(e.value)
