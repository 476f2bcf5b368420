"""The environment in the commands: ``simkit sky --environment`` (state counts, DOPs of the received satellites,
the masked sky plot), ``simkit plot`` (the line-of-sight figure) and ``simkit score`` (errors per class of epochs)."""
import json

import numpy as np
import pytest

import simkit
from simkit.scenario import resolve

from cli_errors import assert_clean_error, run_cli

SITE = ["--lat", "34.2", "--lon", "108.9", "--height", "401.2", "--start", "2026-04-27T06:00:00Z"]


def _all_column(stdout):
    """The token index of the 'all' count in the epoch rows (one per system before it; the date and the time are
    two tokens where the header has 'UTC')."""
    header = next(ln.split() for ln in stdout.splitlines() if ln.startswith("UTC"))
    return header.index("all") + 1


def test_sky_with_an_environment_counts_each_state(tmp_path):
    out = run_cli(["sky", *SITE, "--hours", "1", "--step", "900", "--environment", str(resolve("urban_canyon")),
                   "--plot", "sky.png"], tmp_path)
    assert out.returncode == 0, out.stderr
    rows = [ln.split() for ln in out.stdout.splitlines() if ln.startswith("2026-04-27")]
    col = _all_column(out.stdout)
    assert len(rows) == 5
    for r in rows:
        total, direct, both, nlos, blocked = int(r[col]), *(int(x) for x in r[-4:])
        assert total == direct + both + nlos          # received: direct, direct + reflection, NLOS
        assert blocked > direct                       # a 20 m x 60 m canyon hides most of the sky
    assert (tmp_path / "sky.png").stat().st_size > 5000
    open_sky = run_cli(["sky", *SITE, "--hours", "1", "--step", "900"], tmp_path)
    n_open = [int(ln.split()[_all_column(open_sky.stdout)]) for ln in open_sky.stdout.splitlines()
              if ln.startswith("2026-04-27")]
    assert all(int(r[-4]) + int(r[-3]) + int(r[-2]) + int(r[-1]) == n for r, n in zip(rows, n_open))


def test_sky_environment_bad_input(tmp_path):
    (tmp_path / "none.toml").write_text("[scenario]\nname = 'x'\n")
    assert_clean_error(["sky", *SITE, "--environment", "none.toml"], tmp_path,
                       expect="--environment: none.toml: no [environment] table")
    (tmp_path / "bad.toml").write_text("[environment]\ncanyon = { width_m = 10.0 }\n")
    assert_clean_error(["sky", *SITE, "--environment", "bad.toml"], tmp_path,
                       expect="bad.toml: environment.canyon[0].height_m: missing required key")
    assert_clean_error(["sky", *SITE, "--environment", "missing.toml"], tmp_path,
                       expect="--environment: missing.toml: no such scenario file (bundled scenarios: ")
    (tmp_path / "folder").mkdir()
    assert_clean_error(["sky", *SITE, "--environment", "folder"], tmp_path,
                       expect="--environment: folder: is a directory, expected a scenario TOML file")


def test_sky_environment_takes_a_bundled_scenario_name(tmp_path):
    """`--environment urban_canyon` from any folder, as `simkit run urban_canyon` (docs/urban.md): the same
    table as the bundled file's path gives (the name was read as a path: "cannot read")."""
    args = ["sky", *SITE, "--hours", "0.5", "--step", "900", "--environment"]
    by_name = run_cli(args + ["urban_canyon"], tmp_path)
    by_path = run_cli(args + [str(resolve("urban_canyon"))], tmp_path)
    assert by_name.returncode == 0, by_name.stderr
    rows = lambda out: [ln for ln in out.stdout.splitlines() if ln.startswith("2026-04-27")]  # noqa: E731
    assert rows(by_name) and rows(by_name) == rows(by_path)


@pytest.fixture(scope="module")
def urban(tmp_path_factory):
    return simkit.run("urban_canyon", out=tmp_path_factory.mktemp("ucli") / "u.h5",
                      overrides={"scenario.duration_s": 60.0, "gnss.truth_errors.model": "none"})  # the canyon alone


def test_plot_draws_the_line_of_sight_figure(urban):
    out = run_cli(["plot", urban.name, "--out", "figs"], urban.parent)
    assert out.returncode == 0, out.stderr
    assert (urban.parent / "figs" / "line_of_sight.png").stat().st_size > 5000
    assert (urban.parent / "figs" / "sky.png").stat().st_size > 5000


def test_score_splits_the_epochs_by_line_of_sight(urban, tmp_path):
    """SPP on the canyon: its errors inside (NLOS epochs) are several times those in the open square."""
    sol = simkit.solve(urban, ["spp"])["spp"]
    sc = simkit.score(urban, sol)
    assert {"direct", "nlos"} <= set(sc.by_state)
    assert sum(v["epochs"] for v in sc.by_state.values()) == sc.meta["epochs_scored"]
    rms = {k: v["statistics"]["horizontal"]["rms"] for k, v in sc.by_state.items()}
    assert rms["nlos"] > 3 * rms["direct"]
    assert sc.by_state["nlos"]["satellites_per_antenna"]["blocked"] > 10
    from simkit.io import write_solution

    write_solution(urban, "spp", sol)
    out = run_cli(["score", urban.name, urban.name, "--solution", "spp", "--json", str(tmp_path / "s.json")],
                  urban.parent)
    assert out.returncode == 0, out.stderr
    assert "## By line-of-sight state" in out.stdout
    doc = json.loads((tmp_path / "s.json").read_text())
    assert np.isclose(doc["by_line_of_sight"]["nlos"]["statistics"]["horizontal"]["rms"], rms["nlos"])
