"""The kf15_dd figures of docs/estimators.md, each one command (JSON on stdout):

``python -m studies.estimators_dd compare FILE [--skip S] [--set key=value ...]``
    pitch / roll / heading RMS against the file's truth (after ``--skip`` s) of kf15, kf15_dd and kf21 with
    the attitude solver's attitude (``attitude_source = "auto"``: the solver's attitude with 3+ antennas, else
    the truth plus noise; the source is printed); ``--set`` goes to all three filters.
``python -m studies.estimators_dd nees SCENARIO [--runs N] [--seconds S] [--skip S] [--set ...]
[--override scenario.key=value ...]``
    attitude NEES (3 dof, the phi block) of kf15_dd over ``N`` simulated runs (seeds 1..N) of SCENARIO against
    the two-sided 95 % chi-square bounds of an N-run average; prints the epoch-averaged mean and the fraction
    of epochs inside the bounds.
Nothing here is used by the filters.
"""
from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np

from simkit.io import open_dataset
from simkit.estimators.registry import SOLVERS
from simkit.referee.stats import mean_bounds, reduced_nees
from studies.consistency import error_states
from studies.evaluate import errors_vs_truth

RUNS = {"kf15": {}, "kf15_dd": {}, "kf21": {"attitude_source": "auto"}}


def attitude_rms(ds, sol, skip_s: float) -> dict:
    """RMS (deg) of the pitch, roll and heading errors after ``skip_s`` s."""
    t, _, _, de = errors_vs_truth(ds, sol)
    m = t >= skip_s
    r = np.degrees(np.sqrt(np.mean(de[m] ** 2, axis=0)))
    return {"pitch_deg": round(float(r[0]), 5), "roll_deg": round(float(r[1]), 5),
            "heading_deg": round(float(r[2]), 5), "epochs": int(m.sum())}


def compare(path, skip_s: float = 60.0, params: dict | None = None) -> dict:
    out = {}
    with open_dataset(path) as ds:
        for name, own in RUNS.items():
            sol = SOLVERS[name](ds, {**(params or {}), **own}, False)
            out[name] = attitude_rms(ds, sol, skip_s)
            if name == "kf15_dd":
                used = sol.extras["dd_rows"] > 0
                out[name]["dd_epochs"], out[name]["dd_rejected"] = sol.config["dd_epochs"], sol.config["dd_rejected"]
                out[name]["dd_nis_mean_per_row"] = round(float(np.mean(sol.extras["dd_nis"][used] /
                                                                       sol.extras["dd_rows"][used])), 3)
            if name == "kf21":
                out[name]["attitude_source"] = sol.config["attitude_source"]
    out["file"], out["skip_s"], out["params"] = str(path), skip_s, params or {}
    return out


def truth_at(ds, t):
    k = np.clip(np.searchsorted(ds["truth/t"][:], t - 1e-9), 0, ds["truth/t"].shape[0] - 1)
    return ds["truth/quat_nb"][:][k], ds["truth/vel_enu"][:][k], ds["truth/pos_lla"][:][k]


def attitude_nees(scenario: str, runs: int = 10, seconds: float = 300.0, skip_s: float = 60.0,
                  params: dict | None = None, workdir=None, overrides=()) -> dict:
    """Monte Carlo attitude NEES of kf15_dd (see the module docstring)."""
    from simkit.pipeline import run as simulate

    values = []
    with tempfile.TemporaryDirectory(dir=workdir) as d:
        for i in range(runs):
            path = simulate(scenario, out=Path(d) / f"r{i}.h5", seed=1 + i,
                            overrides=[f"scenario.duration_s={seconds}", *overrides])
            with open_dataset(path) as ds:
                sol = SOLVERS["kf15_dd"](ds, {**(params or {}), "seed": 1 + i}, False)
                e = error_states(sol, *truth_at(ds, sol.t))
                m = sol.t >= skip_s
                values.append(reduced_nees(e[m, 0:3], sol.cov[m, 0:3, 0:3])[0])
    k = min(v.size for v in values)
    avg = np.mean([v[:k] for v in values], axis=0)
    lo, hi = mean_bounds(3 * runs, runs)
    return {"scenario": scenario, "overrides": list(overrides), "runs": runs, "seconds": seconds, "skip_s": skip_s,
            "epochs": k,
            "nees_mean": round(float(avg.mean()), 3), "bounds_95": [round(lo, 3), round(hi, 3)],
            "fraction_inside": round(float(np.mean((avg >= lo) & (avg <= hi))), 3), "dof": 3}


def _params(pairs) -> dict:
    from simkit.params import parse_set

    return parse_set(pairs or [], prefix="")  # TOML literals, as simkit solve --set


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m studies.estimators_dd", description=__doc__.splitlines()[0])
    p.add_argument("study", choices=("compare", "nees"))
    p.add_argument("target", help="a simkit file (compare) or a scenario name (nees)")
    p.add_argument("--skip", type=float, default=60.0, help="seconds left out of the statistics")
    p.add_argument("--runs", type=int, default=10)
    p.add_argument("--seconds", type=float, default=300.0)
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="estimator parameter")
    p.add_argument("--override", action="append", default=[], metavar="KEY=VALUE", help="scenario override (nees)")
    a = p.parse_args(argv)
    if a.study == "compare":
        res = compare(a.target, a.skip, _params(a.set))
    else:
        res = attitude_nees(a.target, a.runs, a.seconds, a.skip, _params(a.set), overrides=a.override)
    print(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
