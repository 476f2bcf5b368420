"""One bad-input base: every stage's input error is a ``simkit.errors.InputError`` (a ``ValueError``), and the CLI
ends any of them with one line and exit 2."""
import importlib
import pkgutil

import numpy as np
import pytest

import simkit
from simkit.ambiguity import AmbiguityInputError, ils
from simkit.errors import InputError, SimkitError
from tests.cli_errors import run_cli

STAGE_ERRORS = [("simkit.errors", "ScenarioError"), ("simkit.errors", "DataFileError"),
                ("simkit.errors", "OutputError"),
                ("simkit.ambiguity", "AmbiguityInputError"), ("simkit.attitude", "AttitudeInputError"),
                ("simkit.estimators", "EstimatorInputError"), ("simkit.campaign", "CampaignInputError"),
                ("simkit.constellation.errors", "ConstellationInputError"), ("simkit.referee", "RefereeInputError"),
                ("simkit.validation.errors", "ValidationInputError"),
                ("simkit.gnss.differencing", "DifferencingInputError"), ("simkit.plots.common", "PlotDependencyError")]


@pytest.mark.parametrize("module, name", STAGE_ERRORS)
def test_each_stage_input_error_is_an_input_error_with_exit_2(module, name):
    cls = getattr(importlib.import_module(module), name)
    assert issubclass(cls, InputError) and issubclass(cls, ValueError)
    assert cls.exit_code == 2


def _all_subclasses(cls):
    for sub in cls.__subclasses__():
        yield sub
        yield from _all_subclasses(sub)


def test_every_simkit_error_in_the_package_is_an_input_error():
    """Walks every module (what a command can raise): no user-facing error outside the one base."""
    for info in pkgutil.walk_packages(simkit.__path__, "simkit."):
        if info.name != "simkit.__main__":  # runs the CLI when imported
            importlib.import_module(info.name)
    outside = [f"{c.__module__}.{c.__name__}" for c in _all_subclasses(SimkitError)
               if not issubclass(c, InputError) and c.__module__.startswith("simkit")]
    assert not outside


def test_an_ambiguity_input_error_ends_the_cli_with_one_line_and_exit_2(tmp_path, monkeypatch):
    """The solver's own error (Q not positive definite) raised inside a command: exit 2 like every stage's."""
    import simkit.commands.inspect as inspect_cmd

    def solve_a_bad_problem(args):
        ils(np.zeros(2), np.diag([1.0, -1.0]))  # an indefinite covariance

    monkeypatch.setattr(inspect_cmd, "run", solve_a_bad_problem)
    proc = run_cli(["inspect", "any.h5"], tmp_path)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1 and "Q" in lines[0] and "Traceback" not in proc.stderr, proc.stderr


def test_input_error_reads_what_then_message_and_survives_a_pickle():
    """Campaign workers send errors between processes: the one-line text must come back unchanged."""
    import pickle

    err = AmbiguityInputError("Q[3]", "not positive definite")
    back = pickle.loads(pickle.dumps(err))
    assert str(back) == str(err) == "Q[3]: not positive definite"
    assert isinstance(back, InputError)
