"""Every figure renders headless (Agg) to a non-empty PNG: the file overview of ``simkit plot`` (trajectory, sky,
satellites and DOPs, IMU Allan deviation, observation errors, a stored solution against truth with +-3 sigma)
and the score figures."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import simkit
import simkit.frames
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
    expected = {f"{name}.png" for name in FIGURES if name != "line_of_sight"} | {   # no [environment]
        f"solution_demo/errors_{k}.png" for k in ("position", "velocity", "attitude")} | {
        "solution_demo/consistency.png"}
    written = {str(p.relative_to(figs)) for p in figs.rglob("*.png")}
    assert written == expected
    assert all(_is_png(figs / name) for name in written)
    # the bar counts the solutions too (their scoring and figures sat at "6/6": 4-8 s on a 24 h file)
    total = len(FIGURES) + 1
    assert f"{total}/{total}" in out.stderr


def test_plot_bad_input_is_one_clean_line(h5):
    (h5.parent / "afile").write_text("x")
    assert_clean_error(["plot", "nothere.h5", "--out", "p2"], h5.parent, expect="nothere.h5: no such file")
    assert_clean_error(["plot", h5.name, "--out", "afile"], h5.parent, expect="--out: afile exists and is not a dir")


def test_a_failed_plot_leaves_no_folder_and_a_good_one_moves_into_place(tmp_path):
    from simkit.plots import staged_directory

    with pytest.raises(RuntimeError):
        with staged_directory(tmp_path / "figs") as tmp:
            (tmp / "half.png").write_bytes(PNG)
            raise RuntimeError("drawing failed")
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "figs").mkdir()
    (tmp_path / "figs" / "mine.txt").write_text("kept")
    with staged_directory(tmp_path / "figs") as tmp:
        (tmp / "sub").mkdir()
        (tmp / "sub" / "a.png").write_bytes(PNG)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["figs"]
    assert sorted(str(p.relative_to(tmp_path / "figs")) for p in (tmp_path / "figs").rglob("*")) == [
        "mine.txt", "sub", "sub/a.png"]


def test_a_figure_that_cannot_be_drawn_is_skipped_with_one_line(tmp_path):
    from simkit.plots.common import draw, require_matplotlib

    plt = require_matplotlib()
    lines = []

    def broken(plt_):
        plt_.figure()
        raise TypeError("cannot unpack non-iterable NoneType object")

    assert draw(plt, tmp_path / "x.png", broken, on_skip=lines.append) is None
    assert lines == ["plot: skipped x.png: TypeError: cannot unpack non-iterable NoneType object"]
    assert not (tmp_path / "x.png").exists() and plt.get_fignums() == []


@pytest.mark.slow   # about 4 s of matplotlib rendering
def test_spp_like_covariance_with_nan_blocks_and_a_two_antenna_attitude_are_plotted(h5, tmp_path):
    """The defect's two stops: the SPP covariance (NaN position-velocity blocks, NaN at epochs without a
    velocity) and an Euler-only attitude with its roll NaN by design."""
    from simkit.io import read_solution
    from simkit.plots import file_figures

    truth = referee.read_truth(h5)
    k = np.arange(0, len(truth.t), 20)
    cov = np.full((len(k), 6, 6), np.nan)
    cov[:, :3, :3], cov[::2, 3:, 3:] = np.eye(3) * 0.04, np.eye(3) * 0.01
    eul = simkit.frames.euler_from_attitude(Rotation.from_quat(truth.quat_nb[k]))
    eul[:, 1] = np.nan
    sols = {"spp_like": Solution(t=truth.t[k], pos_ecef=truth.pos_ecef[k] + 0.1, vel_enu=truth.vel_enu[k],
                                 cov=cov, state_names=("pos_e", "pos_n", "pos_u", "vel_e", "vel_n", "vel_u")),
            "two_antennas": Solution(t=truth.t[k], euler=eul + 0.001, cov=np.broadcast_to(
                np.eye(2) * 1e-6, (len(k), 2, 2)).copy(), state_names=("pitch", "heading"))}
    path = tmp_path / "q.h5"
    path.write_bytes(h5.read_bytes())
    for name, sol in sols.items():
        write_solution(path, name, sol)
    assert read_solution(path, "two_antennas").quat_nb is None
    skipped = []
    (tmp_path / "figs").mkdir()
    paths = file_figures(path, tmp_path / "figs", on_skip=skipped.append)
    assert skipped == []
    written = {str(p.relative_to(tmp_path / "figs")) for p in paths if "solution_" in str(p)}
    assert {"solution_spp_like/errors_position.png", "solution_spp_like/errors_velocity.png",
            "solution_spp_like/consistency.png", "solution_two_antennas/errors_attitude.png",
            "solution_two_antennas/consistency.png"} <= written


def test_sky_plot_has_a_legend_and_its_whole_title(tmp_path, monkeypatch):
    """``simkit sky --plot``: one legend entry per system drawn, and the title (a long source path) inside the
    figure rather than cut at its edges."""
    import matplotlib.figure

    saved, original = [], matplotlib.figure.Figure.savefig

    def capture(fig, *args, **kwargs):
        fig.canvas.draw()
        title = fig.axes[0].title.get_window_extent()
        saved.append((fig.axes[0].get_legend(), title, fig.bbox))
        return original(fig, *args, **kwargs)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", capture)
    out = run_cli(["sky", "--lat", "34.2", "--lon", "108.9", "--start", "2026-04-27T06:00:00Z", "--hours", "1",
                   "--plot", "sky.png"], tmp_path)
    assert out.returncode == 0, out.stderr
    (legend, title, box), = saved
    assert legend is not None
    assert sorted(t.get_text() for t in legend.get_texts()) == ["BeiDou", "GPS"]
    assert box.x0 <= title.x0 and title.x1 <= box.x1 and title.y1 <= box.y1
    assert _is_png(tmp_path / "sky.png")
