"""``simkit score`` from the command line: HDF5 and CSV estimates, JSON / Markdown / report outputs, exit 1 on a
failed spec, and bad input as one clean line (exit 2, nothing written)."""
import json

import numpy as np
import pytest

import simkit
from simkit import referee
from simkit.io import write_solution
from simkit.solution import Solution

from cli_errors import assert_clean_error, digest, run_cli


@pytest.fixture(scope="module")
def work(tmp_path_factory):
    d = tmp_path_factory.mktemp("score_cli")
    h5 = simkit.run("quickstart", out=d / "q.h5", overrides=["scenario.duration_s=8"])
    truth = referee.read_truth(h5)
    k = np.arange(0, len(truth.t), 10)
    offset = np.array([0.0, 0.0, 0.5])          # +0.5 m along ECEF z: within 1 m of the truth everywhere
    cov = np.broadcast_to(np.eye(3) * 0.01, (len(k), 3, 3)).copy()   # 0.1 m sd: overconfident for 0.5 m
    write_solution(h5, "kf", Solution(t=truth.t[k], pos_ecef=truth.pos_ecef[k] + offset,
                                      vel_enu=truth.vel_enu[k], quat_nb=truth.quat_nb[k], cov=cov,
                                      state_names=("pos_e", "pos_n", "pos_u")))
    (d / "est.csv").write_text("t_s,x_ecef_m,y_ecef_m,z_ecef_m\n" + "".join(
        f"{float(t)!r},{float(p[0])!r},{float(p[1])!r},{float(p[2]) + 0.5!r}\n"
        for t, p in zip(truth.t[k], truth.pos_ecef[k])))
    week, sow = referee.file_start(h5)
    (d / "gpst.csv").write_text("gps_week,gps_sow,x_ecef_m,y_ecef_m,z_ecef_m\n" + "".join(
        f"{week},{sow + float(t)!r},{float(p[0])!r},{float(p[1])!r},{float(p[2])!r}\n"
        for t, p in zip(truth.t[k], truth.pos_ecef[k])))
    (d / "pass.toml").write_text("[limits]\nposition_3d = { max_m = 1.0 }\n")
    (d / "strict.toml").write_text("[limits]\nposition_3d = { rms_m = 0.1 }\n[consistency]\n"
                                   "nees_min_fraction_inside = 0.9\n")
    (d / "typo.toml").write_text("[limits]\nposition3d = { max_m = 1.0 }\n")
    (d / "outside.csv").write_text("t_s,x_ecef_m,y_ecef_m,z_ecef_m\n1000,1,2,3\n")
    (d / "broken.csv").write_text("t_s,x_ecef_m,y_ecef_m,z_ecef_m\n0,1,2,3\n1,1,two,3\n")
    (d / "partial.csv").write_text("t_s,lat_deg,lon_deg\n0,1,2\n")
    return d


def test_score_h5_solution_with_json(work):
    out = run_cli(["score", "q.h5", "q.h5", "--spec", "pass.toml", "--json", "s.json"], work)
    assert out.returncode == 0, out.stderr
    assert "| position_3d | m |" in out.stdout and "**Verdict: PASS**" in out.stdout
    payload = json.loads((work / "s.json").read_text())
    assert payload["estimate"] == "q.h5:/solutions/kf"
    assert payload["statistics"]["position_3d"]["max"] == pytest.approx(0.5, abs=1e-6)
    assert payload["nees"]["mean"] == pytest.approx(25.0, rel=1e-6)       # (0.5 m / 0.1 m)^2


@pytest.mark.slow   # four figures: about 4 s of matplotlib rendering
def test_score_report_writes_markdown_and_error_plots(work):
    out = run_cli(["score", "q.h5", "q.h5", "--report", "rep"], work)
    assert out.returncode == 0, out.stderr
    pngs = sorted(p.name for p in (work / "rep").glob("*.png"))
    assert pngs == ["consistency.png", "errors_attitude.png", "errors_position.png", "errors_velocity.png"]
    assert "![errors_position](errors_position.png)" in (work / "rep" / "report.md").read_text()


def test_score_csv_and_a_failing_spec_exits_1(work):
    out = run_cli(["score", "q.h5", "est.csv", "--spec", "strict.toml"], work)
    assert out.returncode == 1
    assert "FAIL: position_3d.rms_m <= 0.1 (value 0.5)" in out.stdout
    assert "FAIL: NEES inside its 95% chi-square bounds at >= 90% of epochs (value -)" in out.stdout


def test_csv_in_gps_time_is_aligned_by_the_file_start(work):
    out = run_cli(["score", "q.h5", "gpst.csv", "--json", "g.json"], work)
    assert out.returncode == 0, out.stderr
    payload = json.loads((work / "g.json").read_text())
    assert payload["meta"]["epochs_scored"] == 81 and payload["statistics"]["position_3d"]["max"] < 1e-6


@pytest.mark.parametrize("args, expect", [
    (["score", "q.h5", "outside.csv"], "outside.csv: estimate epochs (1000.000 .. 1000.000 s) do not overlap"),
    (["score", "q.h5", "broken.csv"], "broken.csv:3: expected numbers separated by commas"),
    (["score", "q.h5", "partial.csv"], "partial.csv: position: missing column(s) h_m"),
    (["score", "q.h5", "missing.csv"], "missing.csv: no such file"),
    (["score", "q.h5", "q.h5", "--solution", "nope"], "no solution 'nope' (stored: kf)"),
    (["score", "q.h5", "q.h5", "--spec", "typo.toml"], "limits.position3d: unknown quantity (did you mean "),
    (["score", "q.h5", "q.h5", "--json", "nodir/s.json"], "--json: nodir/s.json: directory 'nodir' does not exist"),
    (["score", "est.csv", "q.h5"], "est.csv: not an HDF5 file"),
    # an output is never an input of the same command
    (["score", "q.h5", "q.h5", "--json", "q.h5"], "--json: q.h5: is an input of this command"),
    (["score", "q.h5", "est.csv", "--json", "est.csv"], "--json: est.csv: is an input of this command"),
    (["score", "q.h5", "q.h5", "--spec", "pass.toml", "--json", "pass.toml"], "--json: pass.toml: is an input"),
])
def test_bad_input_is_one_clean_line(work, args, expect):
    before = {name: digest(work / name) for name in ("q.h5", "est.csv", "pass.toml")}
    assert_clean_error(args, work, expect=expect)
    assert {name: digest(work / name) for name in before} == before


def test_every_new_command_has_help(work):
    for verb in ("score", "plot", "regress"):
        out = run_cli([verb, "--help"], work)
        assert out.returncode == 0 and "usage: simkit " + verb in out.stdout
