"""``simkit solve``: writes /solutions/<name> with the declared fields, replaces only its own group, and meets bad
input with one clean line (exit 2) before any work."""
import json

import numpy as np
import pytest

import simkit
from cli_errors import assert_clean_error, run_cli
from simkit.io import read_solution, solution_names


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    d = tmp_path_factory.mktemp("solve")
    return simkit.run("quickstart", out=d / "q.h5", overrides=["scenario.duration_s=20"])


def test_solve_writes_each_filter_group(small):
    args = ["solve", str(small), "--filter", "spp", "--filter", "kf15", "--filter", "hinf", "--filter", "kf21",
            "--set", "estimator.gnss=truth", "--set", "estimator.align=static", "-q"]
    proc = run_cli(args, small.parent)
    assert proc.returncode == 0, proc.stderr
    assert {"spp", "kf15", "hinf", "kf21"} <= set(solution_names(small))
    kf = read_solution(small, "kf15")
    assert kf.cov.shape == (kf.t.size, 15, 15) and kf.state_names[0] == "phi_e"
    assert kf.config["params"]["gnss"] == "truth" and kf.config["estimator"] == "kf15"
    assert {"gyro_bias", "accel_bias", "lever_arm", "nis"} <= set(kf.extras)
    hf = read_solution(small, "hinf")
    assert (hf.extras["existence_margin"] > 0).all() and np.isfinite(hf.extras["gamma"]).all()
    k21 = read_solution(small, "kf21")
    assert k21.cov.shape[1] == 18 and "lever_x" in k21.state_names
    sp = read_solution(small, "spp")
    assert sp.pos_ecef.shape == (sp.t.size, 3) and sp.quat_nb is None


def test_a_resolve_replaces_only_its_own_group(small):
    run_cli(["solve", str(small), "--filter", "spp", "-q"], small.parent)
    before = read_solution(small, "spp")
    proc = run_cli(["solve", str(small), "--filter", "kf15", "--name", "kf15_b", "--set",
                    "estimator.gnss=truth", "--set", "estimator.align=static", "--set", "estimator.seed=3", "-q"],
                   small.parent)
    assert proc.returncode == 0, proc.stderr
    after = read_solution(small, "spp")
    assert np.array_equal(before.pos_ecef, after.pos_ecef, equal_nan=True)
    assert read_solution(small, "kf15_b").config["params"]["seed"] == 3


@pytest.mark.parametrize("args, expect", [
    (["--filter", "nosuch"], "unknown filter 'nosuch'"),
    (["--filter", "kf15", "--set", "estimator.nosuch=1"], "estimator.nosuch: unknown key"),
    (["--filter", "kf15", "--set", "gnss=truth"], "expected a key of the form estimator.<name>"),
    (["--filter", "kf15", "--set", "estimator.gnss"], "expected estimator.key=value"),
    (["--filter", "kf15", "--set", "estimator.gnss=magic"], "estimator.gnss: expected 'spp' or 'truth'"),
    (["--filter", "kf15", "--set", "estimator.align=upside"], "estimator.align: expected"),
    (["--filter", "spp", "--filter", "kf15", "--name", "x"], "--name: only valid with exactly one --filter"),
    (["--filter", "spp", "--set", "estimator.antenna=7"], "estimator.antenna: expected 0 .. 1"),
    (["--filter", "hinf", "--set", "estimator.alpha=0.5"], "estimator.alpha: expected > 1"),
    (["--filter", "hinf", "--set", "estimator.alpha=abc"], "estimator.alpha: expected a number, got 'abc'"),
    (["--filter", "kf15", "--set", "estimator.p0_pos_m=[1, 2]"], "estimator.p0_pos_m: expected a list of 3"),
    (["--filter", "kf15", "--set", "estimator.cov_dt_s=0"], "estimator.cov_dt_s: expected a positive"),
    (["--filter", "attitude", "--set", "estimator.validation=strict"], "estimator.validation: 'strict'; expected one"),
    (["--filter", "attitude", "--set", "estimator.pf=2"], "estimator.pf: 2; expected a probability in (0, 1)"),
    (["--filter", "attitude", "--set", "estimator.float_epochs=0"], "estimator.float_epochs: 0; expected an integer"),
    (["--filter", "attitude", "--set", "estimator.attitude=quat"], "estimator.attitude: 'quat'; expected one of"),
    (["--filter", "tdcp", "--set", "estimator.lever_rate=gps"], "estimator.lever_rate: 'gps'; expected one of"),
])
def test_bad_arguments_fail_cleanly(small, args, expect):
    assert_clean_error(["solve", str(small), *args, "-q"], small.parent, expect=expect)


def test_missing_and_foreign_files_fail_cleanly(tmp_path):
    assert_clean_error(["solve", str(tmp_path / "none.h5")], tmp_path, expect="no such file")
    (tmp_path / "x.h5").write_text("not hdf5")
    assert_clean_error(["solve", str(tmp_path / "x.h5")], tmp_path, expect="not an HDF5 file")


def test_help_lists_the_options(tmp_path):
    proc = run_cli(["solve", "--help"], tmp_path)
    assert proc.returncode == 0 and "--filter" in proc.stdout and "--set" in proc.stdout
    assert json.dumps  # the config attribute is JSON: read back above through read_solution


def test_attitude_solvers_are_merged_and_get_the_keys_no_estimator_knows(small, monkeypatch):
    import importlib.machinery
    import sys
    import types

    from simkit.solution import Solution

    seen = {}

    def fake(ds, params, progress):
        seen.update(params)
        t = ds["gnss/t"][:]
        return Solution(t=t, euler=np.zeros((t.size, 3)), config={"estimator": "fake"})

    module = types.ModuleType("simkit.attitude")
    module.__spec__ = importlib.machinery.ModuleSpec("simkit.attitude", None)
    module.SOLVERS = {"fake_attitude": fake}
    monkeypatch.setitem(sys.modules, "simkit.attitude", module)
    proc = run_cli(["solve", str(small), "--filter", "fake_attitude", "--filter", "spp", "--set",
                    "estimator.baseline_m=3.5", "--set", "estimator.elevation_mask_deg=15.0", "-q"], small.parent)
    assert proc.returncode == 0, proc.stderr
    assert seen == {"baseline_m": 3.5}
    assert read_solution(small, "spp").config["elevation_mask_deg"] == 15.0
    assert "fake_attitude" in solution_names(small)


def test_the_referee_reads_the_filter_states_with_their_own_definitions(small):
    """The referee's NEES over the navigation states of a kf15 solution (phi, dv, d_lat/d_lon/d_h by name, with
    the filter's sign and radian conventions) equals the NEES of the filter's own error definition."""
    from simkit.estimators import SOLVERS
    from simkit.estimators.consistency import error_states, nees
    from simkit.referee.compare import compare
    from simkit.referee.truth import read_truth

    with simkit.open(small) as ds:
        sol = SOLVERS["kf15"](ds, {"gnss": "truth", "align": "static"}, False)
    truth = read_truth(small)
    err = compare(truth, sol)
    nav = list(range(9))
    ours = np.stack([err.state(n) for n in sol.state_names[:9]], axis=1)
    with simkit.open(small) as ds:
        t = ds["truth/t"][:]
        k = np.searchsorted(t, sol.t[err.index])
        ref = error_states(sol, ds["truth/quat_nb"][:][k], ds["truth/vel_enu"][:][k], ds["truth/pos_lla"][:][k])
    cov = sol.cov[err.index][:, :9, :9]
    np.testing.assert_allclose(ours, ref[err.index][:, nav], rtol=1e-4, atol=1e-12)
    np.testing.assert_allclose(nees(ours, cov), nees(ref[err.index][:, nav], cov), rtol=1e-3)
