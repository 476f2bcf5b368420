"""Every solution simkit writes is scored and plotted: each solver of ``simkit solve`` on
shortened quickstart (two antennas: the attitude solvers give pitch and heading, roll NaN by design),
airborne_stim300 and xian_static_bds; scoring states what a solution does not estimate, the filters' figures carry
their +-3 sigma bands, and no figure is skipped."""
import numpy as np
import pytest

import simkit
from simkit import referee
from simkit.api import registry
from simkit.io import open_dataset, read_solution, write_solution
from simkit.plots import file_figures

FILTERS = ("kf15", "kf15_dd", "kf21", "hinf")
# (scenario, solvers, parameters per solver); MC-LAMBDA needs 3 antennas, xian's static receiver a static alignment
CASES = [("quickstart", ("spp", *FILTERS, "attitude", "attitude_c", "tdcp"), {}),
         ("airborne_stim300", ("spp", *FILTERS, "attitude", "attitude_c", "attitude_mc", "tdcp"), {}),
         ("xian_static_bds", ("spp", *FILTERS, "attitude", "attitude_c", "attitude_mc", "tdcp"),
          {f: {"align": "static"} for f in FILTERS})]
PARTS = {"position": "errors_position", "velocity": "errors_velocity", "attitude": "errors_attitude"}


def _solve_all(path, names, params):
    solvers = registry()
    with open_dataset(path) as ds:
        sols = {n: solvers[n](ds, params.get(n, {})) for n in names}
    for n, sol in sols.items():
        write_solution(path, n, sol)


@pytest.mark.slow   # every solver on three 40 s scenarios, numba compiles on the first run: a few minutes
@pytest.mark.parametrize("scenario, names, params", CASES, ids=[c[0] for c in CASES])
def test_every_solver_output_is_scored_and_plotted(tmp_path, scenario, names, params):
    path = simkit.run(scenario, out=tmp_path / "s.h5", overrides=["scenario.duration_s=40"])
    _solve_all(path, names, params)
    truth = referee.read_truth(path)
    n_ant = truth.lever_arm_b.shape[0]
    expected = set()
    for name in names:
        sol = read_solution(path, name)
        sc = referee.score(truth, sol, where=name)
        missing = sc.meta["not_estimated"]
        assert sc.statistics, name
        if name in ("spp", "tdcp"):
            assert sc.meta["point"] == "antenna:0"
        if name in FILTERS:
            assert sc.meta["point"] == "imu" and missing == []
            for part in ("pos_enu", "vel_enu", "euler"):   # the +-3 sigma bands of the plots
                assert np.isfinite(sc.bands[part][-1]).all(), (name, part)
        if name.startswith("attitude"):
            assert {"position", "velocity"} <= set(missing)
            assert ("roll" in missing) == (n_ant == 2), name
            assert sc.nees is not None and sc.nees["epochs"] > 0, name
        expected |= {f"solution_{name}/{fig}.png" for part, fig in PARTS.items() if part not in missing}
    skipped = []
    (tmp_path / "figs").mkdir()
    paths = file_figures(path, tmp_path / "figs", on_skip=skipped.append)
    assert skipped == []
    written = {str(p.relative_to(tmp_path / "figs")) for p in paths}
    assert expected <= written
