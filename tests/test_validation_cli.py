"""``simkit validate``: scenario and file inputs agree, JSON and report outputs, exit codes, one-line errors."""
import json

import pytest

import simkit
from cli_errors import assert_clean_error, digest, run_cli

SHORT = ["--set", "scenario.duration_s=600", "--set", "gnss.rate_hz=0.1", "--no-progress"]


def test_help(tmp_path):
    proc = run_cli(["validate", "--help"], tmp_path)
    assert proc.returncode == 0 and "--json" in proc.stdout and "--report" in proc.stdout


@pytest.mark.slow  # matplotlib: ~7 s
def test_scenario_json_and_report(tmp_path):
    proc = run_cli(["validate", "xian_static_bds", *SHORT, "--json", "v.json", "--report", "rep"], tmp_path)
    assert proc.returncode == 0, proc.stderr
    s = json.loads((tmp_path / "v.json").read_text())
    assert s["epochs"] == 61 and set(s["configurations"]) == {"dual", "three"}
    assert s["configurations"]["three"]["lengths_m"] == [3.965, 9.445]
    for c in ("C1", "C2", "C3", "C4", "C5"):
        assert s["claims"][c]["held"] and s["claims"][c]["checked"] > 0
    for c in ("C6", "C7", "C7_all_visible"):
        assert 0.0 <= s["claims"][c]["fraction"] <= 1.0
    # every satellite count from 2 to all visible was checked, with the claimed ranks
    top = s["visible"]["max"]
    assert set(s["ranks"]["dual/highest"]) == {str(k) for k in range(2, top + 1)}
    assert s["ranks"]["dual/highest"]["2"] == {"1": 61} and s["ranks"]["three/highest"]["2"] == {"2": 61}
    assert all(set(d) == {"3"} for k, d in s["ranks"]["three/highest"].items() if k != "2")
    text = (tmp_path / "rep" / "report.md").read_text()
    assert "| C5 | mathematical |" in text and "fig3_pitch.png" in text
    assert {p.name for p in (tmp_path / "rep").glob("*.png")} == {"fig2_visible.png", "fig3_pitch.png",
                                                                  "fig4_roll.png", "fig5_yaw.png"}


def test_file_input_matches_scenario_input(tmp_path):
    overrides = ["scenario.duration_s=600", "gnss.rate_hz=0.1", "imu.preset=ideal"]
    h5 = simkit.run("xian_static_bds", out=tmp_path / "x.h5", overrides=overrides)
    a = run_cli(["validate", str(h5), "--json", "f.json", "--no-progress"], tmp_path)
    b = run_cli(["validate", "xian_static_bds", *sum([["--set", o] for o in overrides], []), "--json", "s.json",
                 "--no-progress"], tmp_path)
    assert a.returncode == 0 and b.returncode == 0, a.stderr + b.stderr
    fa, fb = (json.loads((tmp_path / n).read_text()) for n in ("f.json", "s.json"))
    assert fa["epochs"] == fb["epochs"] and fa["ranks"] == fb["ranks"]
    assert fa["claims"]["C6"]["fraction"] == pytest.approx(fb["claims"]["C6"]["fraction"], abs=0.02)


@pytest.mark.parametrize("args, expect", [
    (["validate", "nosuch"], "no such scenario file"),
    (["validate", "xian_static_bds", "--set", "gnss.foo=1"], "gnss.foo"),
    (["validate", "missing.h5"], "missing.h5: no such file"),
    (["validate", "xian_static_bds", "--json", "nodir/v.json"], "does not exist"),
    (["validate", "xian_static_bds", "--random", "-1"], "--random"),
    (["validate", "xian_static_bds", "--random-stride", "0"], "--random-stride"),
    (["validate", "missing.h5", "--set", "a=1"], "--set"),
    (["validate", "xian_static_bds", "--weighting", "bogus"], "--weighting"),
    (["validate", "xian_static_bds", "--systems", "G", *SHORT], "--systems: no satellite"),
    (["validate", "xian_static_bds", "--json", "."], "--json: .: is a directory"),  # a traceback
])
def test_bad_input_is_one_line(tmp_path, args, expect):
    assert_clean_error(args, tmp_path, expect=expect)


def test_the_json_never_replaces_the_file_read(tmp_path):
    """Regression: `validate F.h5 --json F.h5` replaced the file (truth and solutions lost)."""
    h5 = simkit.run("quickstart", out=tmp_path / "F.h5", overrides=["scenario.duration_s=2"])
    before = digest(h5)
    assert_clean_error(["validate", "F.h5", "--json", "F.h5"], tmp_path, expect="--json: F.h5: is an input")
    assert_clean_error(["validate", "F.h5", "--report", "F.h5"], tmp_path, expect="exists and is not a folder")
    assert digest(h5) == before


def test_single_antenna_scenario_is_refused(tmp_path):
    assert_clean_error(["validate", "xian_static_bds", "--set", "gnss.antenna=[{lever_arm_m=[0,0,0]}]"],
                       tmp_path, expect="at least 2 antennas")
