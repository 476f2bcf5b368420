"""pytest plugin: regression-test your own scenarios against golden statistics.

Enable it in your ``conftest.py`` with ``pytest_plugins = ["simkit.referee.pytest_plugin"]``, then::

    def test_my_scenario(simkit_regress):
        simkit_regress("scenarios/my_run.toml", "tests/golden/my_run.json", duration_s=10)

The first run (or ``pytest --simkit-update-golden``) writes the golden file; later runs fail with the list of
quantities that drifted, each with its golden and new value (see :mod:`simkit.referee.regress`).
"""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from . import regress


def pytest_addoption(parser):
    parser.addoption("--simkit-update-golden", action="store_true", default=False,
                     help="rewrite the golden statistics of simkit_regress scenarios instead of comparing")


@pytest.fixture
def simkit_regress(request, tmp_path):
    """``check(scenario, golden_path, duration_s=5.0, overrides=())``: compare or (first run / update) write."""
    update = request.config.getoption("--simkit-update-golden", default=False)

    def check(scenario, golden_path, duration_s: float = regress.DEFAULT_SHORT_S, overrides=()):
        golden_path = Path(golden_path)
        name = Path(str(scenario)).stem
        if update or not golden_path.is_file():
            entry = regress.golden_entry(scenario, duration_s, overrides, tmp_path)
            golden_path.parent.mkdir(parents=True, exist_ok=True)
            golden_path.write_text(json.dumps({name: entry}, indent=1, sort_keys=True))
            return []
        entry = regress.load_golden(golden_path)[name]
        drifts = regress.check(name, scenario, {**entry, "overrides": list(overrides)}, (), tmp_path)
        if drifts:
            pytest.fail("scenario regression:\n" + "\n".join(str(d) for d in drifts), pytrace=False)
        return drifts

    return check
