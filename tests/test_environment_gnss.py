"""The GNSS stage under an environment (the bundled urban_canyon, shortened): what each line-of-sight state does
to the observables, determinism and block-split independence, and no change at all without [environment]."""
import numpy as np
import pytest

import simkit
from simkit.gnss import signals
from simkit.io import open_dataset, read_gnss

SHORT = {"scenario.duration_s": 50.0, "gnss.errors.receiver_clock": False}   # its random walk is not in Doppler
ALPHA = 10 ** (-6.0 / 20)                   # the default reflection_loss_db
SPACING = 0.5                               # the default correlator spacing, chips


@pytest.fixture(scope="module")
def urban(tmp_path_factory):
    d = tmp_path_factory.mktemp("urban")
    return simkit.run("urban_canyon", out=d / "u.h5", overrides=SHORT)


def _read(path):
    with open_dataset(path) as ds:
        return read_gnss(ds, obs=("code", "carrier", "doppler", "cn0", "lli", "ambiguity"),
                         truth=("los_state", "nlos_delay", "range", "L1C/multipath_code", "L1C/multipath_carrier",
                                "B1I/multipath_code", "L1C/multipath_rate", "L1C/noise_carrier",
                                "L1C/noise_doppler"), satellites=False)


def test_states_drive_the_observables(urban):
    g = _read(urban)
    st, delay = g.truth["los_state"], g.truth["nlos_delay"]
    assert {0, 1, 2, 3, 255} <= set(np.unique(st))
    for sig in ("L1C", "B1I"):
        code = g.obs["code"][sig]
        above = st != 255
        assert np.isnan(code[st == 3]).all()                              # blocked: not tracked
        mp = g.truth[f"{sig}/multipath_code"]
        nl = (st == 2) & np.isfinite(code)
        assert nl.sum() > 100
        np.testing.assert_array_equal(mp[nl], delay[nl])                  # NLOS: the whole extra path
        two = (st == 1) & np.isfinite(code)
        assert two.sum() > 5
        bound = ALPHA * SPACING / 2 * signals.get(sig).chip_length_m
        assert (np.abs(mp[two]) <= bound + 1e-9).all()                    # two-ray: inside the DLL envelope
        assert (delay[st == 0] == 0).all() and np.isnan(delay[above & (st == 3)]).all()
    lam = signals.get("L1C").wavelength_m
    carrier_mp = g.truth["L1C/multipath_carrier"]
    two = (st == 1) & np.isfinite(g.obs["carrier"]["L1C"])
    assert (np.abs(carrier_mp[two]) <= np.arcsin(ALPHA) * lam / (2 * np.pi) + 1e-12).all()


def test_nlos_doppler_carries_the_extra_path_rate(urban):
    """On NLOS channels the truth's multipath rate is the derivative of the extra path (difference quotient of
    nlos_delay at 5 Hz), and the Doppler agrees with the time-differenced carrier (which holds the extra path)."""
    g = _read(urban)
    st, car, dop = g.truth["los_state"], g.obs["carrier"]["L1C"], g.obs["doppler"]["L1C"]
    amb, delay, rate = g.obs["ambiguity"]["L1C"], g.truth["nlos_delay"], g.truth["L1C/multipath_rate"]
    dt = np.diff(g.t)[:, None, None]
    same = (st[1:] == 2) & (st[:-1] == 2) & (amb[1:] == amb[:-1]) & np.isfinite(car[1:]) & np.isfinite(car[:-1])
    assert same.sum() > 50
    quotient = np.diff(delay, axis=0) / dt
    np.testing.assert_allclose(quotient[same], 0.5 * (rate[1:] + rate[:-1])[same], atol=2e-4)
    lam = signals.get("L1C").wavelength_m
    clean_car = car - amb - g.truth["L1C/noise_carrier"] / lam        # the thermal noise draws left out
    clean_dop = dop - g.truth["L1C/noise_doppler"]
    tdcp = -np.diff(clean_car, axis=0) / dt
    # what is left: the midpoint rule over 0.2 s on the range acceleration of a car at 2 m/s^2
    assert np.nanmax(np.abs(tdcp - 0.5 * (clean_dop[1:] + clean_dop[:-1]))[same]) < 0.05


def test_loss_of_lock_and_switch_to_a_reflection_reacquire_with_lli(urban):
    g = _read(urban)
    st, lli, amb = g.truth["los_state"], g.obs["lli"]["L1C"], g.obs["ambiguity"]["L1C"]
    tracked = np.isfinite(g.obs["code"]["L1C"])
    was, now = tracked[:-1], tracked[1:]
    back = ~was & now                                                    # (re)acquired
    switch = was & now & ((st[1:] == 2) != (st[:-1] == 2))               # direct <-> reflection only
    assert back[5:].sum() > 0 and switch.sum() > 0
    assert (lli[1:][back | switch] & 1).all()
    assert (amb[1:][switch] != amb[:-1][switch]).mean() > 0.99           # a new integer (the odd tie: same draw)
    steady = was & now & ~switch
    assert (lli[1:][steady] == 0).mean() > 0.99


def test_same_seed_same_arrays_and_block_split_independent(urban, tmp_path):
    from simkit.pipeline import run

    other = run("urban_canyon", out=tmp_path / "u2.h5", overrides=SHORT, block_samples=777)
    a, b = _read(urban), _read(other)
    for kind in ("code", "carrier", "doppler"):        # float rounding of block-wise truth sums (as for quickstart)
        for sig in ("L1C", "B1I"):
            np.testing.assert_allclose(a.obs[kind][sig], b.obs[kind][sig], rtol=0, atol=1e-6)
    for sig in ("L1C", "B1I"):
        np.testing.assert_array_equal(a.obs["lli"][sig], b.obs["lli"][sig])
        np.testing.assert_array_equal(a.obs["ambiguity"][sig], b.obs["ambiguity"][sig])
    np.testing.assert_array_equal(a.truth["los_state"], b.truth["los_state"])
    again = simkit.run("urban_canyon", out=tmp_path / "u3.h5", overrides=SHORT)
    c = _read(again)
    for kind in ("code", "carrier", "doppler", "lli"):
        for sig in ("L1C", "B1I"):
            np.testing.assert_array_equal(a.obs[kind][sig], c.obs[kind][sig])


def test_no_environment_table_no_new_datasets(tmp_path):
    out = simkit.run("quickstart", out=tmp_path / "q.h5", overrides={"scenario.duration_s": 3.0})
    with open_dataset(out) as ds:
        g = read_gnss(ds, truth=("los_state", "nlos_delay", "L1C/multipath_rate"), satellites=False)
    assert g.truth == {}
