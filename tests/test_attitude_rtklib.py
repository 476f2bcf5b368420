"""Moving baselines on airborne_stim300: simkit's single-epoch attitude solvers beside RTKLIB's moving-base mode
(pyrtklib postpos, continuous ambiguity resolution) on the RINEX export of the same file, in one run."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import simkit
from cli_errors import run_cli
from simkit.attitude import SOLVERS

pytestmark = pytest.mark.slow  # a 1000 s, 100 Hz flight and an RTKLIB run (about 30 s)


def _rtklib_moving_base(rover, base, nav, out):
    """RTKLIB moving-base baseline rover - base in ENU (m) and its quality flag, per output epoch (GPST)."""
    import pyrtklib as p

    popt, sopt = p.prcopt_default, p.solopt_default
    popt.mode, popt.navsys, popt.nf, popt.modear = p.PMODE_MOVEB, p.SYS_GPS | p.SYS_CMP, 1, 1  # continuous AR
    popt.elmin = np.radians(10.0)
    sopt.posf = p.SOLF_ENU
    buf = p.Arr1Dchar(1024)
    for i, c in enumerate(str(out) + "\0"):
        buf[i] = c
    files = [str(rover), str(base), str(nav)]
    assert p.postpos(p.gtime_t(), p.gtime_t(), 0.0, 0.0, popt, sopt, p.filopt_t(), files, 3, buf, "", "") == 0
    rows = [line.split() for line in open(out) if not line.startswith("%")]
    hms = np.array([[float(x) for x in r[1].split(":")] for r in rows])
    sod = hms @ [3600.0, 60.0, 1.0]
    return sod, np.array([[float(x) for x in r[2:5]] for r in rows]), np.array([int(r[5]) for r in rows])


def test_simkit_fixes_moving_baselines_at_least_as_often_as_rtklib(tmp_path):
    h5 = simkit.run("airborne_stim300", out=tmp_path / "air.h5")
    assert run_cli(["rinex", str(h5), "-o", str(tmp_path / "rnx")], tmp_path).returncode == 0
    rnx = tmp_path / "rnx"
    nav = next(rnx.glob("BRDM*.rnx"))
    with simkit.open(h5) as ds:
        tt, qt = ds["truth/t"][:], ds["truth/quat_nb"][:]
        lever = ds["gnss/antennas/lever_arm_b"][:]
        sols = {n: SOLVERS[n](ds, {"continuity": 0}, False) for n in ("attitude", "attitude_c", "attitude_mc")}
        start_sod = ds.attrs["start_gps_sow"] % 86400.0
    F = (lever[1:] - lever[0]).T
    truth = lambda t: np.einsum("kij,jr->kri", Rotation.from_quat(qt[np.searchsorted(tt, t)]).as_matrix(), F)
    report = []
    for name, sol in sols.items():
        st = sol.extras["status"]
        err = np.linalg.norm(sol.extras["baseline_enu"] - truth(sol.t), axis=2)[st == 1]
        report.append((name, np.mean(st == 1), int(np.sum(st == 3)), err.max(axis=0)))
    for k in (1, 2):
        sod, b, q = _rtklib_moving_base(next(rnx.glob(f"*ant{k}.rnx")), next(rnx.glob("*ant0.rnx")), nav,
                                        tmp_path / f"moveb{k}.pos")
        t = sod - start_sod
        err = np.linalg.norm(b - truth(t)[:, k - 1], axis=1)
        wrong = int(np.sum(err[q == 1] > 0.05))  # a fix 5 cm off is a wrong integer (19-24 cm wavelengths)
        report.append((f"RTKLIB moving-base ant{k}", np.sum(q == 1) / len(sols["attitude"].t), wrong,
                       np.sort(err[q == 1])[-1 - wrong]))
    print("\n".join(f"{n}: fixed {f:.4f}, wrong {w}, max error of the right fixes {np.round(e, 4)} m"
                    for n, f, w, e in report))
    rtk_rate = min(r[1] for r in report[3:])
    for name, rate, wrong, max_err in report[:3]:
        assert wrong == 0 and rate >= rtk_rate and np.all(max_err < 0.02), (name, rate, wrong, max_err)
