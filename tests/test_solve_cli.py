"""``simkit solve``: writes /solutions/<name> with the declared fields, replaces only its own group, and meets bad
input with one clean line (exit 2) before any work."""
import json

import numpy as np
import pytest

import simkit
from cli_errors import assert_clean_error, digest, run_cli
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
    (["--filter", "kf15", "--set", "estimator.gnss=magic"], "estimator.gnss: expected one of spp, truth, got 'magic'"),
    (["--filter", "kf15", "--set", "estimator.align=upside"], "estimator.align: expected"),
    (["--filter", "spp", "--filter", "kf15", "--name", "x"], "--name: only valid with exactly one --filter"),
    (["--filter", "spp", "--set", "estimator.antenna=7"], "estimator.antenna: expected 0 .. 1 ("),
    (["--filter", "hinf", "--set", "estimator.alpha=0.5"], "estimator.alpha: expected > 1"),
    (["--filter", "hinf", "--set", "estimator.alpha=abc"], "estimator.alpha: expected a number, got 'abc'"),
    (["--filter", "kf15", "--set", "estimator.p0_pos_m=[1, 2]"], "estimator.p0_pos_m: expected a list of 3"),
    (["--filter", "kf15", "--set", "estimator.cov_dt_s=0"], "estimator.cov_dt_s: expected a number > 0, got 0"),
    (["--filter", "attitude", "--set", "estimator.validation=strict"],
     "estimator.validation: expected one of pf, ratio, ffrt, none, got 'strict'"),
    (["--filter", "attitude", "--set", "estimator.pf=2"],
     "estimator.pf: expected a probability in (0, 1), got 2"),
    (["--filter", "attitude", "--set", "estimator.float_epochs=0"],
     "estimator.float_epochs: expected an integer >= 1, got 0"),
    (["--filter", "attitude", "--set", "estimator.attitude=quat"],
     "estimator.attitude: expected one of wls, svd, badshah, baseline"),
    (["--filter", "tdcp", "--set", "estimator.lever_rate=gps"],
     "estimator.lever_rate: expected one of attitude, imu, got 'gps'"),
    # one schema for every solver: booleans are never numbers, integers are not floats
    (["--filter", "attitude", "--set", "estimator.mask_deg=true"], "estimator.mask_deg: expected a number, got True"),
    (["--filter", "kf15", "--set", "estimator.elevation_mask_deg=true"],
     "estimator.elevation_mask_deg: expected a number, got True"),
    (["--filter", "spp", "--set", "estimator.antenna=1.5"], "estimator.antenna: expected an integer, got 1.5"),
    (["--filter", "spp", "--set", "estimator.systems='GX'"], "estimator.systems: expected distinct letters of G, C"),
    (["--filter", "spp", "--set", "estimator.systems='GG'"], "estimator.systems: expected distinct letters of G, C"),
    (["--filter", "tdcp", "--set", "estimator.antenna=1.0"], "estimator.antenna: expected an integer, got 1.0"),
    (["--filter", "tdcp", "--set", "estimator.antenna=2"], "estimator.antenna: expected 0 .. 1 ("),
    (["--filter", "attitude", "--set", "estimator.every=2.0"], "estimator.every: expected an integer, got 2.0"),
    (["--filter", "attitude", "--set", "estimator.static=true"], "estimator.static: expected an integer (0 or 1)"),
    (["--filter", "attitude", "--set", "estimator.static=2"], "estimator.static: expected one of 0, 1, got 2"),
    (["--filter", "attitude", "--set", "estimator.stop_s=nan"], "estimator.stop_s: expected a finite number"),
    (["--filter", "kf15", "--set", "estimator.align=attitude"], "estimator.align: 'attitude' needs 3 or more"),
    (["--filter", "spp", "--filter", "attitude", "--set", "estimator.nosuch=1"], "estimator.nosuch: unknown key"),
    # a solution name is one HDF5 group name
    (["--filter", "spp", "--name", "../evil"], "--name: expected letters, digits"),
    (["--filter", "spp", "--name", "my sol"], "--name: expected letters, digits"),
    (["--filter", "spp", "--name", ".tmp"], "--name: expected letters, digits"),
])
def test_bad_arguments_fail_cleanly(small, args, expect):
    before = digest(small)
    assert_clean_error(["solve", str(small), *args, "-q"], small.parent, expect=expect)
    assert digest(small) == before


def test_every_filter_is_checked_before_any_runs(small):
    """Regression: a bad value for the second filter leaves the file byte for byte as it was (it used to
    rewrite /solutions/spp first)."""
    before = digest(small)
    assert_clean_error(["solve", str(small), "--filter", "spp", "--filter", "kf15", "--set",
                        "estimator.gnss=banana", "-q"], small.parent, expect="estimator.gnss: expected one of")
    assert_clean_error(["solve", str(small), "--filter", "spp", "--filter", "attitude", "--set",
                        "estimator.mask_deg=true"], small.parent, expect="estimator.mask_deg")
    assert digest(small) == before


def test_a_filter_that_fails_on_its_data_writes_nothing_and_the_others_run(small):
    """Regression: MC-LAMBDA needs 3 antennas and the file has 2 (/gnss/antennas/lever_arm_b): one line naming
    the filter, no /solutions/attitude_mc group, spp still written, exit 1."""
    with simkit.open(small) as ds:
        assert ds["gnss/antennas/lever_arm_b"].shape[0] == 2
    proc = run_cli(["solve", str(small), "--filter", "attitude_mc", "--filter", "spp", "-q"], small.parent)
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert proc.returncode == 1, proc.stderr
    assert len(lines) == 1 and lines[0].startswith("simkit solve: attitude_mc: failed:") and "3 antennas" in lines[0]
    assert "Traceback" not in proc.stderr
    assert "attitude_mc" not in solution_names(small) and "spp" in solution_names(small)


def test_every_default_passes_its_own_schema():
    """The schema agrees with every declared default (a default it refused would make the solver unusable)."""
    from simkit.attitude.params import AMBIGUITY_DEFAULTS, TDCP_DEFAULTS
    from simkit.estimators.registry import DEFAULTS
    from simkit.params import check_value, spec

    for defaults in (*DEFAULTS.values(), AMBIGUITY_DEFAULTS, TDCP_DEFAULTS):
        for key, value in defaults.items():
            assert check_value(spec(key, value), value) == value, key


def test_numbers_from_numpy_are_numbers_and_bools_are_not():
    from simkit.attitude.params import AMBIGUITY_DEFAULTS, merge
    from simkit.attitude import AttitudeInputError

    p = merge(AMBIGUITY_DEFAULTS, {"max_sats": np.int64(5), "mask_deg": np.float32(12.5)}, "attitude")
    assert p["max_sats"] == 5 and p["mask_deg"] == 12.5 and type(p["mask_deg"]) is float
    for bad in ({"max_sats": np.bool_(True)}, {"mask_deg": False}, {"every": 1.5}):
        with pytest.raises(AttitudeInputError):
            merge(AMBIGUITY_DEFAULTS, bad, "attitude")


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
    from simkit.referee.compare import compare
    from simkit.referee.stats import reduced_nees
    from simkit.referee.truth import read_truth
    from studies.consistency import error_states

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
    np.testing.assert_allclose(reduced_nees(ours, cov)[0], reduced_nees(ref[err.index][:, nav], cov)[0], rtol=1e-3)


@pytest.mark.slow
def test_a_cold_numba_cache_is_announced_once(small, tmp_path):
    """Regression: the first `simkit solve` sat silent ~40 s while numba compiled. With an empty cache
    (NUMBA_CACHE_DIR) the command says so; once the kernels are cached it does not."""
    import os
    import subprocess
    import sys

    from cli_errors import ROOT

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), SIMKIT_NO_PREPARED_CACHE="1",
               PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
    cold = "from simkit.api import kernels_cold; print(kernels_cold([\"kf15\"]))"
    probe = lambda: subprocess.run([sys.executable, "-c", cold], env=env, capture_output=True, text=True,  # noqa: E731
                                   cwd=ROOT).stdout.strip()
    solve = ["solve", str(small), "--filter", "kf15", "--name", "numba_probe", "--set", "estimator.gnss=truth",
             "--set", "estimator.align=static"]
    assert probe() == "True"
    first = subprocess.run([sys.executable, "-m", "simkit", *solve], env=env, capture_output=True, text=True)
    assert first.returncode == 0, first.stderr
    assert "compiling the filter kernels (first run only, cached)" in first.stderr
    assert probe() == "False"
    again = subprocess.run([sys.executable, "-m", "simkit", *solve], env=env, capture_output=True, text=True)
    assert again.returncode == 0 and "compiling" not in again.stderr, again.stderr
