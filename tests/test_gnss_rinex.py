"""RINEX 3.04 export: read back by georinex, and RTKLIB (pyrtklib postpos) fixes the simulated baseline."""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_gnss_observables import NAV, SOW, WEEK, make, static_truth  # noqa: E402

from simkit.pipeline import gnss_rows, gnss_static_rows  # noqa: E402

from simkit.gnss import rinex  # noqa: E402


def simulate(extra, duration):
    sim = make(extra, duration=duration)
    t = sim.epoch_times()
    out = gnss_rows(sim.process(t, *static_truth(t)), prefix="")
    out.update(gnss_static_rows(sim.static(), prefix=""))
    return sim, out


def test_rinex_read_back_by_georinex(tmp_path):
    import georinex
    sim, out = simulate({"signals": ["L1C", "L2W", "B1I"]}, 20.0)
    paths = rinex.export(out, WEEK, SOW, tmp_path, [str(NAV)], "sim")
    assert [p.name for p in paths] == ["sim_ant0.rnx", "sim_ant1.rnx", "sim_ant2.rnx", NAV.name]
    obs = georinex.load(paths[1])
    checked = 0
    for sv in obs.sv.values:
        s = sim.sat_ids.index(str(sv))
        for sig in ("L1C", "L2W", "B1I"):
            code, phase, dop, snr = sim.signals[sim.cfg.signals.index(sig)].rinex_codes()
            if code not in obs or np.isnan(out[f"obs/{sig}/code"][:, 1, s]).all():
                continue
            for field, name in ((code, "code"), (phase, "carrier"), (dop, "doppler"), (snr, "cn0")):
                got = obs[field].sel(sv=sv).values
                want = out[f"obs/{sig}/{name}"][:, 1, s]
                np.testing.assert_allclose(got, want, atol=6e-4, equal_nan=True)
                checked += 1
    assert checked >= 40


def test_rtklib_fixes_the_simulated_baseline(tmp_path):
    import pyrtklib as rtk
    sim, out = simulate({"signals": ["L1C", "L2W"], "clock": "per_antenna",
                         "antenna": [{"lever_arm_m": [0.0, 0.0, 0.0]}, {"lever_arm_m": [3.965, 1.0, 0.3]}]}, 300.0)
    paths = rinex.export(out, WEEK, SOW, tmp_path, [str(NAV)], "sim")
    truth = out["truth/antenna_pos_ecef"][0]
    opt = rtk.prcopt_default
    opt.mode, opt.nf, opt.navsys = rtk.PMODE_STATIC, 2, rtk.SYS_GPS
    opt.elmin, opt.modear = np.radians(10.0), 3
    opt.ionoopt, opt.tropopt, opt.refpos = rtk.IONOOPT_BRDC, rtk.TROPOPT_SAAS, 0
    for i in range(3):
        opt.rb[i] = float(truth[0, i])  # base antenna at its true position
    sol = rtk.solopt_default
    sol.posf = rtk.SOLF_XYZ
    outfile = str(tmp_path / "out.pos")
    buf = rtk.Arr1Dchar(len(outfile) + 1)
    for i, ch in enumerate(outfile):
        buf[i] = ch
    files = [str(paths[1]), str(paths[0]), str(paths[2])]
    assert rtk.postpos(rtk.gtime_t(), rtk.gtime_t(), 0.0, 0.0, opt, sol, rtk.filopt_t(), files, len(files), buf,
                       "", "") == 0
    rows = [ln.split() for ln in Path(outfile).read_text().splitlines() if ln and ln[0] != "%"]
    q = np.array([int(r[5]) for r in rows])
    xyz = np.array([[float(v) for v in r[2:5]] for r in rows])
    fixed = q == 1
    err = np.linalg.norm(xyz[fixed] - truth[1], axis=1)
    base_true = truth[1] - truth[0]
    print(f"\nRTKLIB: {fixed.sum()}/{len(q)} epochs fixed; baseline {np.linalg.norm(base_true):.4f} m; "
          f"max error of fixed baseline {err.max() * 1e3:.2f} mm, last {err[-1] * 1e3:.2f} mm")
    assert fixed[-60:].all()
    assert err.max() < 0.01


def test_marker_type_and_name_follow_the_vehicle(tmp_path):
    """RINEX 3.04 MARKER TYPE: GEODETIC only for a static antenna; AIRBORNE for a climbing aircraft, GROUND_CRAFT
    for a car; the marker name separates the stem from the antenna index."""
    import simkit
    from simkit.commands.rinex import run as rinex_cmd

    cases = {"xian_static_bds": ("GEODETIC", ["scenario.duration_s=5"]),
             "airborne_stim300": ("AIRBORNE", ["scenario.duration_s=200"]),
             "quickstart": ("GROUND_CRAFT", ["scenario.duration_s=30"])}
    for name, (kind, over) in cases.items():
        path = simkit.run(name, out=tmp_path / f"{name}.h5", overrides=over)
        out = tmp_path / name

        class Args:
            file, name = str(path), None
        Args.out = str(out)
        rinex_cmd(Args)
        head = (out / f"{name}_ant0.rnx").read_text().split("END OF HEADER")[0]
        assert f"{kind:<60}MARKER TYPE" in head, name
        assert f"{name.upper()}_ANT0" in head


def test_rinex_export_of_an_imported_file_is_one_line(tmp_path):
    """An imported real file has no simulated receiver clock (its time tags already are receiver time): the
    export says so in one line, exit 2, and creates no output folder (it was a KeyError traceback)."""
    from cli_errors import assert_clean_error
    from realdata_helpers import KMS3_NAV, KMS3_OBS
    from simkit.cli import main

    assert main(["import", str(KMS3_OBS), "--nav", str(KMS3_NAV), "-o", str(tmp_path / "real.h5"), "-q"]) == 0
    assert_clean_error(["rinex", "real.h5", "-o", "out"], tmp_path,
                       expect="real.h5: no /gnss/truth/receiver_clock: the RINEX export needs a simulated file")
