"""Broadcast system-time offsets: evaluated from the navigation file, applied to the simulated ranges of each
system's satellites (truth in /gnss/truth/system_time_offset), and removed by SPP with one receiver clock.

Authority: the numbers of the files themselves, copied here by hand from the RINEX 4 '> STO' records of
BRD400DLR 2023-03-12 (GAGP, BDGP, QZGP) and the RINEX 3.04 'TIME SYSTEM CORR' lines of BRDM00DLR 2023-03-14 and
2026-04-27 (GAGP); the Galileo OS SIS ICD 5.1.8 (GGTO = t_GST - t_GPS = A0G + A1G (t - t0G)). RTKLIB 2.4.3
cannot referee the single-clock case: its pntpos estimates one clock per system and does not apply GGTO.
"""
import h5py
import numpy as np
import pytest

import simkit
from conftest import DATA
from simkit.constellation import load, time_offsets
from simkit.earth import C_LIGHT
from simkit.estimators import SOLVERS
from simkit.gnss.spp import spp
from simkit.io import broadcast_ionosphere, open_dataset, read_gnss

BRD4 = DATA / "rinex_nav" / "BRD400DLR_S_20230710000_01D_MN.rnx.gz"
BRDM23 = DATA / "rinex_nav" / "BRDM00DLR_S_20230730000_01D_MN.rnx"
WEEK = 2253  # 2023-03-12 is its Sunday


def test_offsets_evaluate_the_broadcast_polynomials_by_hand():
    off = load(BRD4).time_offsets
    poly = time_offsets.polynomials(off, "GECJR")
    assert set(poly) == {"E", "C", "J"}  # GPS has none to apply, GLONASS is left out (module docstring)
    sys = np.array(["G", "E", "C", "J", "R"])
    value, rate = time_offsets.evaluate(poly, sys, WEEK, 86400.0 + 3600.0)
    # '> STO E.. IFNV .. GAGP': 1.073931343853e-08 1.86517468137e-14, t_ref 2023-03-13 00:00 = week 2253 86400 s
    gagp = 1.073931343853e-08 + 1.86517468137e-14 * 3600.0
    # '> STO C21 CNVX .. BDGP': -1.542503014207e-08 -4.707345624411e-14, t_ref week 2253 1200 s (GPS time)
    bdgp = -1.542503014207e-08 - 4.707345624411e-14 * (86400.0 + 3600.0 - 1200.0)
    np.testing.assert_allclose(value, [0.0, gagp, bdgp, 0.0, 0.0], rtol=0, atol=1e-22)
    np.testing.assert_array_equal(rate, [0.0, 1.86517468137e-14, -4.707345624411e-14, 0.0, 0.0])
    # RINEX 3 header line 'GAGP  8.3527993411e-09-6.217248938e-15 259200 2253', across a week boundary
    poly3 = time_offsets.polynomials(load(BRDM23).time_offsets, "E")
    v, _ = time_offsets.evaluate(poly3, np.array(["E"]), 2254, 100.0)
    assert v[0] == pytest.approx(8.3527993411e-09 - 6.217248938e-15 * (604800.0 - 259200.0 + 100.0), abs=1e-22)


def _run(tmp_path, name, extra=()):
    over = ["gnss.constellation[0].source='" + str(BRD4) + "'", "scenario.start='2023-03-12T10:00:00Z'",
            "scenario.duration_s=20", 'gnss.signals=["L1C","B1I","E1C","J1C"]', "gnss.truth_errors.model='none'",
            "gnss.errors.noise=false", "gnss.errors.multipath=false", "imu.preset='ideal'", *extra]
    return simkit.run("quickstart", out=tmp_path / name, overrides=over)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("sto")
    return _run(tmp, "on.h5"), _run(tmp, "off.h5", ["gnss.errors.system_time_offset=false"])


def test_offset_enters_each_systems_ranges_and_is_stored_as_truth(runs):
    on, off = runs
    with h5py.File(on) as a, h5py.File(off) as b:
        ids = a["gnss/sat_id"][:].astype(str)
        sys = np.array([s[0] for s in ids])
        assert list(a["gnss/time_offset_systems"][:].astype(str)) == ["C", "E", "J"]
        assert "gnss/time_offset" not in b and "gnss/truth/system_time_offset" not in b
        t = a["gnss/t"][:]
        sow = float(a.attrs["start_gps_sow"]) + t
        truth = a["gnss/truth/system_time_offset"][:]                                    # (M, S) m
        by_hand = {"G": 0.0 * sow,
                   "E": 1.073931343853e-08 + 1.86517468137e-14 * (sow - 86400.0),
                   "C": -1.542503014207e-08 - 4.707345624411e-14 * (sow - 1200.0),
                   "J": 0.0 * sow}
        for s_, expected in by_hand.items():
            cols = sys == s_
            np.testing.assert_allclose(truth[:, cols], -C_LIGHT * expected[:, None] * np.ones((1, cols.sum())),
                                       rtol=0, atol=1e-9)
        for sig, s_ in (("L1C", "G"), ("B1I", "C"), ("E1C", "E"), ("J1C", "J")):
            cols = sys == s_
            ca, cb = a[f"gnss/obs/{sig}/code"][:][..., cols], b[f"gnss/obs/{sig}/code"][:][..., cols]
            assert np.isfinite(ca).any()
            if s_ in "GJ":  # zero offset: bit-identical to the run without the term
                np.testing.assert_array_equal(ca, cb)
                np.testing.assert_array_equal(a[f"gnss/obs/{sig}/carrier"][:][..., cols],
                                              b[f"gnss/obs/{sig}/carrier"][:][..., cols])
                continue
            seen = np.isfinite(ca)
            want = np.broadcast_to(truth[:, None, cols], ca.shape)[seen]
            np.testing.assert_allclose((ca - cb)[seen], want, rtol=0, atol=2e-6)
            lam = C_LIGHT / a["gnss/sat_frequency_hz"][:][cols, list(a["gnss/signals"][:].astype(str)).index(sig)]
            dphi = a[f"gnss/obs/{sig}/carrier"][:][..., cols] - b[f"gnss/obs/{sig}/carrier"][:][..., cols]
            np.testing.assert_allclose((dphi * lam)[seen], want, rtol=0, atol=2e-6)
        np.testing.assert_array_equal(a["gnss/truth/satellite_clock"][:][..., sys == "G"],
                                      b["gnss/truth/satellite_clock"][:][..., sys == "G"])


def test_spp_single_clock_removes_the_broadcast_offsets_per_system_clocks_absorb_them(runs):
    on, _ = runs
    with h5py.File(on) as f:
        truth = f["gnss/truth/antenna_pos_ecef"][:, 0]
    with open_dataset(on) as ds:
        per_system = SOLVERS["spp"](ds, {})
        single = SOLVERS["spp"](ds, {"clock": "single"})
    e_per = np.linalg.norm(per_system.pos_ecef - truth, axis=1)
    e_single = np.linalg.norm(single.pos_ecef - truth, axis=1)
    # the same single-clock solve without the offsets removed: GGTO 10.7 ns and BDGP -15.4 ns (3.2 m, 4.6 m)
    with open_dataset(on) as ds:
        g = read_gnss(ds, antennas=0, obs=("code",))
        iono = broadcast_ionosphere(ds)
        sow = float(ds.attrs["start_gps_sow"]) + g.t
    sys = np.array([s[0] for s in g.sat_id])
    code, gd = np.full(g.sat_clock.shape, np.nan), np.zeros(len(sys))
    for j, sig in enumerate(g.signals):  # each satellite's own system's signal (one per system here)
        take = np.isfinite(g.obs["code"][sig]).any(0) & np.isnan(code).all(0)
        code[:, take], gd[take] = g.obs["code"][sig][:, take], g.group_delay[take, j]
    biased = spp(g.t, code, None, g.sat_wavelength_m[:, 0], g.sat_pos_ecef, g.sat_clock, sys, gd,
                 iono_coefficients=iono, gps_sow=sow, single_clock=True)
    e_biased = np.linalg.norm(biased.pos_ecef - truth, axis=1)
    print(f"\nSPP error-free GPS+BDS+Galileo+QZSS: per-system clocks max {e_per.max() * 1e3:.2f} mm, single clock with "
          f"offsets removed max {e_single.max() * 1e3:.2f} mm, single clock without {np.median(e_biased):.2f} m")
    assert single.extras["n_sats"].min() >= 15
    assert e_per.max() < 0.005 and e_single.max() < 0.005
    assert np.median(e_biased) > 1.0


def test_bad_clock_choice_is_one_line_exit_2(runs, tmp_path):
    import subprocess
    import sys

    on, _ = runs
    before = on.read_bytes()
    run = subprocess.run([sys.executable, "-m", "simkit", "solve", str(on), "--filter", "spp", "--set",
                          "estimator.clock='both'"], capture_output=True, text=True)
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1
    assert "estimator.clock" in run.stderr and "per-system, single" in run.stderr
    assert on.read_bytes() == before
