"""Every figure renders headless (Agg) to a non-empty PNG: the file overview of ``simkit plot`` (trajectory, sky,
satellites and DOPs, IMU Allan deviation, observation errors, a stored solution against truth with +-3 sigma)
and the score figures."""
import numpy as np
import pytest

import simkit
from simkit import referee
from simkit.io import write_solution
from simkit.plots import FIGURES
from simkit.solution import Solution

from cli_errors import assert_clean_error, run_cli

PNG = b"\x89PNG\r\n\x1a\n"


def _is_png(path):
    data = path.read_bytes()
    return data[:8] == PNG and len(data) > 5000


@pytest.fixture(scope="module")
def h5(tmp_path_factory):
    path = simkit.run("quickstart", out=tmp_path_factory.mktemp("plots") / "q.h5",
                      overrides=["scenario.duration_s=12"])
    truth = referee.read_truth(path)
    k = np.arange(0, len(truth.t), 20)
    rng = np.random.default_rng(2)
    cov = np.broadcast_to(np.diag([0.04, 0.04, 0.09]), (len(k), 3, 3)).copy()
    write_solution(path, "demo", Solution(t=truth.t[k], pos_ecef=truth.pos_ecef[k] + 0.2 * rng.standard_normal(
        (len(k), 3)), vel_enu=truth.vel_enu[k], quat_nb=truth.quat_nb[k], cov=cov,
        state_names=("pos_e", "pos_n", "pos_u")))
    return path


@pytest.mark.slow   # about 5 s of matplotlib rendering
def test_simkit_plot_writes_every_figure_as_png(h5):
    out = run_cli(["plot", h5.name, "--out", "figs"], h5.parent)
    assert out.returncode == 0, out.stderr
    figs = h5.parent / "figs"
    expected = {f"{name}.png" for name in FIGURES} | {
        f"solution_demo/errors_{k}.png" for k in ("position", "velocity", "attitude")} | {
        "solution_demo/consistency.png"}
    written = {str(p.relative_to(figs)) for p in figs.rglob("*.png")}
    assert written == expected
    assert all(_is_png(figs / name) for name in written)


def test_plot_bad_input_is_one_clean_line(h5):
    (h5.parent / "afile").write_text("x")
    assert_clean_error(["plot", "nothere.h5", "--out", "p2"], h5.parent, expect="nothere.h5: no such file")
    assert_clean_error(["plot", h5.name, "--out", "afile"], h5.parent, expect="--out: afile exists and is not a dir")
