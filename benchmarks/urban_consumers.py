"""The consumers on ``urban_canyon`` against the same route in open sky (the scenario without [environment],
same seed): SPP and kf15 position errors (``simkit solve`` + ``simkit score``, overall and per line-of-sight class
of the epochs) and RTKLIB's moving-base fix rate between the two roof antennas (pyrtklib ``postpos``, GPS + BDS,
continuous ambiguity resolution, on the RINEX export of each file). Numbers for docs/urban.md.
Run: ``python benchmarks/urban_consumers.py [--seed N]`` (needs pyrtklib, the 'test' extra).
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import tomllib
from pathlib import Path

import numpy as np

import simkit
from simkit.scenario import resolve

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))


def moving_base(rover, base, nav, out):
    """RTKLIB moving-base solution quality flags (1 fix, 2 float, ...) per output epoch."""
    import pyrtklib as p

    popt, sopt = p.prcopt_default, p.solopt_default
    popt.mode, popt.navsys, popt.nf, popt.modear = p.PMODE_MOVEB, p.SYS_GPS | p.SYS_CMP, 1, 1
    popt.elmin = np.radians(10.0)
    sopt.posf = p.SOLF_ENU
    buf = p.Arr1Dchar(1024)
    for i, c in enumerate(str(out) + "\0"):
        buf[i] = c
    assert p.postpos(p.gtime_t(), p.gtime_t(), 0.0, 0.0, popt, sopt, p.filopt_t(),
                     [str(rover), str(base), str(nav)], 3, buf, "", "") == 0
    rows = [line.split() for line in open(out) if not line.startswith("%")]
    return np.array([int(r[5]) for r in rows]), np.array([[float(x) for x in r[2:5]] for r in rows])


def one(label, scenario, d: Path, seed: int, classes_from=None):
    """Run, solve, score and RTKLIB on one scenario; the epochs are classed by the line-of-sight states of the
    file ``classes_from`` (default: this run's own file)."""
    from cli_errors import run_cli
    from simkit.referee import stats
    from simkit.referee.line_of_sight import by_state

    h5 = simkit.run(scenario, out=d / f"{label}.h5", seed=seed)
    sols = simkit.solve(h5, ["spp", "kf15"])
    out = {}
    for name in ("spp", "kf15"):
        sc = simkit.score(h5, sols[name])
        classes = by_state(classes_from or h5, sc.errors, stats.series(sc.errors))
        out[name] = {"all": sc.statistics["horizontal"]["rms"], "3d": sc.statistics["position_3d"]["rms"],
                     **{k: v["statistics"]["horizontal"]["rms"] for k, v in classes.items()},
                     "epochs": {k: v["epochs"] for k, v in classes.items()}}
    assert run_cli(["rinex", str(h5), "-o", str(d / f"rnx_{label}")], d).returncode == 0
    rnx = d / f"rnx_{label}"
    q, b = moving_base(next(rnx.glob("*ant1.rnx")), next(rnx.glob("*ant0.rnx")), next(rnx.glob("BRDM*.rnx")),
                       d / f"{label}.pos")
    with simkit.open(h5) as ds:
        n_epochs = ds["gnss/t"].shape[0]
    out["rtklib"] = {"fixed": float(np.sum(q == 1) / n_epochs), "epochs_out": int(q.size),
                     "wrong": int(np.sum(np.abs(np.linalg.norm(b[q == 1], axis=1) - 2.0) > 0.05))}
    return out, h5


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, default=7)
    args = ap.parse_args()
    urban = tomllib.loads(resolve("urban_canyon").read_text())
    open_sky = {k: v for k, v in urban.items() if k != "environment"}
    with tempfile.TemporaryDirectory() as d:
        res = {}
        res["urban"], urban_h5 = one("urban", urban, Path(d), args.seed)
        res["open"], _ = one("open", open_sky, Path(d), args.seed, classes_from=urban_h5)   # the urban epochs' classes
    for label, r in res.items():
        for name in ("spp", "kf15"):
            x = r[name]
            per = ", ".join(f"{k} {x[k]:.2f} m ({x['epochs'][k]} epochs)" for k in x["epochs"])
            print(f"{label:5s} {name:5s}: horizontal RMS {x['all']:.2f} m, 3D {x['3d']:.2f} m; by class: {per}")
        rt = r["rtklib"]
        print(f"{label:5s} RTKLIB moving-base ant1-ant0: fixed {100 * rt['fixed']:.1f} % of the GNSS epochs "
              f"({rt['epochs_out']} solutions out, {rt['wrong']} fixes with a baseline length off by > 5 cm)")


if __name__ == "__main__":
    main()
