"""The top-level API (``simkit.solve``, ``score``, ``validate``, ``campaign``): the README's examples run as
written, the API gives what the commands write, checks before it runs, and reads the file without changing it."""
import doctest
import re
from pathlib import Path

import numpy as np
import pytest

import simkit
from cli_errors import digest, run_cli
from simkit.errors import SimkitError
from simkit.io import read_solution

README = Path(__file__).resolve().parents[1] / "README.md"


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    d = tmp_path_factory.mktemp("api")
    return simkit.run("quickstart", out=d / "q.h5", overrides=["scenario.duration_s=20"])


def _python_section_blocks() -> str:
    """The ```python blocks of the README's "## Python" section, joined."""
    text = README.read_text()
    section = text[text.index("\n## Python\n"):]
    section = section[:section.index("\n## ", 1)]
    return "\n".join(re.findall(r"```python\n(.*?)```", section, flags=re.S))


def test_the_readme_python_examples_run_as_written(tmp_path, monkeypatch):
    source = _python_section_blocks()
    for name in ("simkit.solve", "simkit.score", "simkit.validate", "simkit.campaign"):
        assert f"{name}(" in source, f"the README's Python section has no example of {name}"
    monkeypatch.chdir(tmp_path)
    test = doctest.DocTestParser().get_doctest(source, {}, "README.md#python", str(README), 0)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    runner.run(test)
    assert runner.summarize(verbose=False).failed == 0
    assert runner.summarize(verbose=False).attempted >= 8


def _same(a, b):
    for field in ("t", "pos_ecef", "vel_enu", "quat_nb", "euler", "cov"):
        x, y = getattr(a, field), getattr(b, field)
        assert (x is None) == (y is None), field
        if x is not None:
            np.testing.assert_array_equal(x, y, err_msg=field)


def test_solve_reads_only_and_returns_what_the_command_writes(small):
    before = digest(small)
    sols = simkit.solve(small, filters=["spp", "kf15"], params={"align": "static"})
    assert digest(small) == before                      # the file is only read
    proc = run_cli(["solve", str(small), "--filter", "spp", "--filter", "kf15", "--set", "estimator.align=static",
                    "-q"], small.parent)
    assert proc.returncode == 0, proc.stderr
    for name in ("spp", "kf15"):
        _same(sols[name], read_solution(small, name))


def test_score_of_a_solution_equals_the_score_of_it_stored(small):
    sols = simkit.solve(small, filters=["kf15"])
    run_cli(["solve", str(small), "--filter", "kf15", "--name", "kf15_api", "-q"], small.parent)
    direct = simkit.score(small, sols["kf15"])
    stored = simkit.score(small, small, solution="kf15_api")
    assert direct.statistics == stored.statistics
    assert direct.meta["epochs_scored"] == sols["kf15"].t.size


def test_solve_checks_every_parameter_before_any_filter_runs(small):
    seen = []
    with pytest.raises(SimkitError, match="estimator.gnss: expected one of"):
        simkit.solve(small, filters=["spp", "kf15"], params={"gnss": "banana"},
                     on_each=lambda *a: seen.append(a))
    with pytest.raises(SimkitError, match="unknown filter 'kf99'"):
        simkit.solve(small, filters=["spp", "kf99"], on_each=lambda *a: seen.append(a))
    assert seen == []


def test_a_filter_failing_on_its_data_is_left_out_and_warned(small):
    """MC-LAMBDA needs 3 antennas; the quickstart file has 2 (/gnss/antennas/lever_arm_b)."""
    with simkit.open(small) as ds:
        assert ds["gnss/antennas/lever_arm_b"].shape[0] == 2
    with pytest.warns(RuntimeWarning, match="attitude_mc: failed: .*3 antennas"):
        sols = simkit.solve(small, filters=["attitude_mc", "spp"])
    assert sorted(sols) == ["spp"]


def test_score_refuses_a_point_for_an_in_memory_solution(small):
    sol = simkit.solve(small, filters=["spp"])["spp"]
    with pytest.raises(SimkitError, match="declares its own point"):
        simkit.score(small, sol, point="imu")


def test_validate_refuses_overrides_for_a_file_and_bad_counts(small):
    with pytest.raises(SimkitError, match="--set"):
        simkit.validate(small, overrides=["scenario.duration_s=10"])
    with pytest.raises(SimkitError, match="--random-stride"):
        simkit.validate(small, random_stride=0)


def test_no_two_classes_of_simkit_share_a_name():
    """Regression: two Truth, InitialState, Geometry and GaussMarkov classes meant an import decided which one a
    reader got (examples/simkit_kf15.py converted referee's InitialState into the estimators' one)."""
    import ast
    import collections

    where = collections.defaultdict(list)
    for path in (README.parent / "simkit").rglob("*.py"):
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, ast.ClassDef):
                where[node.name].append(str(path.relative_to(README.parent)))
    assert {name: paths for name, paths in where.items() if len(paths) > 1} == {}


def test_the_plugin_runner_and_the_euler_atdop_have_names_of_their_own():
    """``simkit.run`` simulates and ``simkit.validation.atdop(L)`` takes a Gramian: the referee's plugin runner
    and the attitude's ATDOP from geometry are exported under other names."""
    from simkit import attitude, referee, validation

    assert "run" not in referee.__all__ and callable(referee.run_filter)
    assert "atdop" not in attitude.__all__ and attitude.euler_atdop is not validation.atdop


def test_simkit_campaign_stays_callable_once_its_sub_package_is_imported(tmp_path):
    """Regression: ``simkit.campaign`` was a function in simkit/__init__.py, and the first import of the
    sub-package (by the call itself) rebound the name to the module: a second call raised TypeError."""
    import importlib

    from simkit.campaign import CampaignInputError

    importlib.import_module("simkit.campaign.stats")
    for _ in range(2):
        with pytest.raises(CampaignInputError, match="--workers"):
            simkit.campaign("quickstart", tmp_path / "c", 1, workers=0)
    assert simkit.campaign.wilson_interval(5, 10)[0] < 0.5 < simkit.campaign.wilson_interval(5, 10)[1]
    assert not (tmp_path / "c").exists()


def test_score_takes_a_spec_as_a_toml_path_or_a_spec(small, tmp_path):
    """A 1 nm limit on the horizontal error fails for any estimate from noisy pseudoranges; the path and the
    loaded Spec give the same checks."""
    from simkit import referee

    spec = tmp_path / "zero.toml"
    spec.write_text("[limits]\nhorizontal = { max_m = 1e-9 }\n")
    sol = simkit.solve(small, filters=["spp"])["spp"]
    by_path = simkit.score(small, sol, spec=spec)
    assert not by_path.passed
    assert by_path.checks == simkit.score(small, sol, spec=referee.load_spec(spec)).checks
