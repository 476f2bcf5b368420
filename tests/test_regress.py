"""``simkit regress``: the bundled golden statistics reproduce; a deliberately changed noise parameter is
detected and named (the gyro white-noise statistics drift, nothing else of the IMU); the pytest fixture writes a
golden file on first use and flags a drift afterwards."""
import json

import pytest

from simkit.referee import regress
from simkit.referee.pytest_plugin import simkit_regress  # noqa: F401  (the fixture users enable as a plugin)

from cli_errors import assert_clean_error, run_cli


def test_bundled_quickstart_matches_its_golden_statistics(tmp_path):
    out = run_cli(["regress", "quickstart"], tmp_path)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "quickstart: 56 quantities, OK" in out.stdout


def test_a_changed_noise_parameter_is_detected_and_named(tmp_path):
    out = run_cli(["regress", "quickstart", "--set", "imu.gyro.arw_deg_per_sqrt_h=0.5"], tmp_path)
    assert out.returncode == 1
    drifted = [ln.split(": ")[1].split(" drifted")[0] for ln in out.stdout.splitlines() if ln.startswith("DRIFT")]
    assert sorted(drifted) == sorted([f"imu/errors/gyro_white.std[{a}]" for a in "xyz"]
                                     + [f"imu/gyro-truth.std[{a}]" for a in "xyz"])
    # ADIS16488's 0.26 deg/sqrt(h) raised to 0.5: the white-noise sd scales by 0.5 / 0.26 = 1.92
    line = next(ln for ln in out.stdout.splitlines() if "gyro_white.std[x]" in ln)
    assert "(+" in line and "92.3 %" in line


def test_compare_names_missing_and_moved_quantities():
    drifts = regress.compare("s", {"a": 1.0, "b": 2.0}, {"a": 1.0 + 1e-7, "b": 2.1, "c": 3.0})
    assert [(d.quantity, d.golden, d.value) for d in drifts] == [("b", 2.0, 2.1), ("c", None, 3.0)]
    assert str(drifts[0]) == "s: b drifted from 2 to 2.1 (+0.1, 5 %)"


def test_pytest_fixture_writes_then_checks_a_users_scenario(simkit_regress, tmp_path):  # noqa: F811
    scenario = tmp_path / "mine.toml"
    from simkit.scenario.loader import resolve

    scenario.write_text(resolve("quickstart").read_text())
    golden = tmp_path / "golden" / "mine.json"
    assert simkit_regress(scenario, golden, duration_s=1.0) == []
    assert json.loads(golden.read_text())["mine"]["duration_s"] == 1.0
    assert simkit_regress(scenario, golden, duration_s=1.0) == []
    with pytest.raises(pytest.fail.Exception, match=r"mine: imu/errors/accel_white.std\[x\] drifted"):
        simkit_regress(scenario, golden, duration_s=1.0, overrides=["imu.accel.vrw_m_per_s_per_sqrt_h=0.5"])


def test_regress_bad_input(tmp_path):
    (tmp_path / "g.json").write_text(json.dumps({"x": {"nope": 1}}))
    assert_clean_error(["regress", "nosuch"], tmp_path, expect="nosuch: not a TOML file, a directory or a bundled")
    assert_clean_error(["regress", "--golden", "g.json"], tmp_path, expect="g.json: x: expected duration_s")


def test_update_writes_a_user_file_and_leaves_the_bundled_one(tmp_path):
    """Regression: `simkit regress --update` rewrote the golden file inside the installed package."""
    from cli_errors import digest, run_cli
    from simkit.referee import regress

    before = digest(regress.GOLDEN)
    proc = run_cli(["regress", "quickstart", "--update"], tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert digest(regress.GOLDEN) == before
    mine = json.loads((tmp_path / "regress_golden.json").read_text())
    bundled = regress.load_golden()
    assert set(mine) == set(bundled)  # started from the bundled table
    assert set(mine["quickstart"]["quantities"]) == set(bundled["quickstart"]["quantities"])
    check = run_cli(["regress", "quickstart", "--golden", "regress_golden.json"], tmp_path)
    assert check.returncode == 0, check.stdout + check.stderr
