"""DD attitude with five systems: Galileo and QZSS join the integer fixing, GLONASS (FDMA) is left out with the
reason given, and fixing is at least as frequent as with GPS + BDS alone, with no wrong fix against the true
integer ambiguities the file holds."""
import numpy as np
import pytest

import simkit
from simkit.attitude import SOLVERS, AttitudeInputError

pytestmark = pytest.mark.slow  # two 5-minute, three-antenna simulations and their solves


def _run(tmp, name, signals):
    return simkit.run("xian_static_bds", out=tmp / f"{name}.h5", overrides=[
        'scenario.start="2026-04-27T06:05:00Z"', "scenario.duration_s=300", "imu.preset=ideal",
        "gnss.constellation=[{source='BRDM00DLR_S_20261170000_01D_MN.rnx.gz'}]", f"gnss.signals={signals}"])


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("att5")
    return _run(tmp, "gc", '["L1C","B1I"]'), _run(tmp, "five", '["L1C","B1I","E1C","G1C"]')


def test_five_systems_fix_at_least_as_often_with_no_wrong_fix(files):
    rates = []
    for path in files:
        with simkit.open(path) as ds:
            sol = SOLVERS["attitude"](ds, {"every": 2}, False)
        st = sol.extras["status"]
        assert (st == 3).sum() == 0  # status 3: a fix that differs from the true integers
        fixed = st == 1
        z, zt = sol.extras["dd_ambiguity"][fixed], sol.extras["dd_ambiguity_true"][fixed]
        assert np.array_equal(z[~np.isnan(z)], zt[~np.isnan(zt)])
        rates.append(fixed.mean())
        if path == files[1]:
            assert sol.config["signals"] == ["L1C", "B1I", "E1C"]  # G1C left out
    print(f"\nDD attitude fix rate: GPS+BDS {rates[0]:.3f}, five systems {rates[1]:.3f}")
    assert rates[1] >= rates[0]


def test_naming_a_glonass_signal_is_refused_with_the_reason(files):
    with simkit.open(files[1]) as ds:
        with pytest.raises(AttitudeInputError, match="G1C.*not integers"):
            SOLVERS["attitude"](ds, {"signals": "L1C,G1C"}, False)


def _rtklib_moving_base(rnx, navsys, out):
    """RTKLIB moving-base baseline ant1 - ant0 (ENU, m) and quality per epoch (continuous AR; GLONASS AR off)."""
    import pyrtklib as p

    popt, sopt = p.prcopt_default, p.solopt_default
    popt.mode, popt.navsys, popt.nf, popt.modear, popt.glomodear = p.PMODE_MOVEB, navsys, 1, 1, 0
    popt.elmin = np.radians(10.0)
    sopt.posf = p.SOLF_ENU
    buf = p.Arr1Dchar(1024)
    for i, c in enumerate(str(out) + "\0"):
        buf[i] = c
    files = [str(next(rnx.glob("*ant1.rnx"))), str(next(rnx.glob("*ant0.rnx"))), str(next(rnx.glob("BRDM*.rnx")))]
    assert p.postpos(p.gtime_t(), p.gtime_t(), 0.0, 0.0, popt, sopt, p.filopt_t(), files, 3, buf, "", "") == 0
    rows = [line.split() for line in open(out) if not line.startswith("%")]
    sod = np.array([[float(x) for x in r[1].split(":")] for r in rows]) @ [3600.0, 60.0, 1.0]
    return sod, np.array([[float(x) for x in r[2:5]] for r in rows]), np.array([int(r[5]) for r in rows])


def test_rtklib_moving_base_on_the_five_system_export_fixes_as_often_with_no_wrong_fix(tmp_path):
    """quickstart (a car, 2 m baseline): RTKLIB's moving-base mode on simkit's RINEX with GPS+BDS and with
    GPS+BDS+Galileo+GLONASS (GLONASS float only, glomodear = 0): fixed at least as often, no fix 5 cm off."""
    import pyrtklib as p
    from scipy.spatial.transform import Rotation

    from simkit.commands.rinex import run as rinex_cmd

    found = {}
    for label, sigs, navsys in (("gc", '["L1C","B1I"]', p.SYS_GPS | p.SYS_CMP),
                                ("five", '["L1C","B1I","E1C","G1C"]', p.SYS_GPS | p.SYS_CMP | p.SYS_GAL | p.SYS_GLO)):
        h5 = simkit.run("quickstart", out=tmp_path / f"{label}.h5", overrides=[f"gnss.signals={sigs}"])

        class Args:
            file, name, out = str(h5), label, str(tmp_path / label)
        rinex_cmd(Args)
        with simkit.open(h5) as ds:
            tt, qt = ds["truth/t"][:], ds["truth/quat_nb"][:]
            lever = ds["gnss/antennas/lever_arm_b"][:]
            start_sod = ds.attrs["start_gps_sow"] % 86400.0
        sod, b, q = _rtklib_moving_base(tmp_path / label, navsys, tmp_path / f"{label}.pos")
        k = np.clip(np.searchsorted(tt, sod - start_sod - 1e-6), 0, len(tt) - 1)
        truth = Rotation.from_quat(qt[k]).apply(lever[1] - lever[0])
        err = np.linalg.norm(b - truth, axis=1)
        found[label] = (int(np.sum(q == 1)), len(q), int(np.sum(err[q == 1] > 0.05)))
    print(f"\nRTKLIB moving base, fixed / epochs / wrong: GPS+BDS {found['gc']}, five systems {found['five']}")
    assert found["five"][2] == 0 and found["gc"][2] == 0
    assert found["five"][0] >= found["gc"][0] > 0.8 * found["gc"][1]


def test_kf15_dd_uses_galileo_and_leaves_glonass_out(tmp_path):
    """kf15_dd on quickstart: with GLONASS G1C added, the DD rows are exactly those of GPS+BDS (the GPS/BDS
    observables are bit-identical and G1C gives none); with Galileo E1C added there are more."""
    from simkit.estimators import SOLVERS as FILTERS

    rows = {}
    for label, sigs in (("gc", '["L1C","B1I"]'), ("glo", '["L1C","B1I","G1C"]'), ("gal", '["L1C","B1I","E1C"]')):
        path = simkit.run("quickstart", out=tmp_path / f"{label}.h5", overrides=[f"gnss.signals={sigs}"])
        with simkit.open(path) as ds:
            sol = FILTERS["kf15_dd"](ds, {})
        assert sol.config["dd_epochs"] > 40 and sol.config["dd_rejected"] == 0
        rows[label] = sol.extras["dd_rows"]
    np.testing.assert_array_equal(rows["glo"], rows["gc"])
    assert rows["gal"].sum() > rows["gc"].sum() + 200
