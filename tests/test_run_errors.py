"""Bad input to ``simkit run``, ``inspect`` and ``rinex``: one line on stderr naming the file / key and what was
expected, exit code 2, no traceback, nothing left on disk."""
import os
import sys
from pathlib import Path

import h5py
import pytest

from cli_errors import ROOT, assert_clean_error, digest, run_cli

GOOD = """[scenario]
name = "tiny"
start = "2026-04-27T06:00:00Z"
duration_s = 2.0

[trajectory]
rate_hz = 10.0
origin = { lat_deg = 34.2, lon_deg = 108.9, height_m = 400.0 }

[[trajectory.segment]]
kind = "static"
duration_s = 2.0
"""
GNSS = """
[gnss]
rate_hz = 1.0
elevation_mask_deg = {mask}
signals = ["L1C"]

[[gnss.constellation]]
source = "{source}"

[[gnss.antenna]]
lever_arm_m = [0.0, 0.0, 0.0]
"""


def _scenario(folder: Path, text: str, name: str = "s.toml") -> str:
    (folder / name).write_text(text)
    return name


RUN_CASES = [
    # (scenario text or None for the bundled quickstart, extra args, expected text in the error line)
    (None, ["--seed", "-1"], "--seed: expected an integer in [0, 2^64 - 1]"),
    (None, ["--seed", str(2**64)], "--seed: expected an integer in [0, 2^64 - 1]"),
    (None, ["--seed", "abc"], "invalid int value"),
    (None, ["--set", "scenario.duration_s=1e9"], "--force to run it anyway"),
    (None, ["--set", "scenario.duration_s=-5"], "scenario.duration_s: must be > 0"),
    (None, ["--set", "scenario.duration_s=nan"], "scenario.duration_s: expected a finite number"),
    (None, ["--set", "scenario.seed=-3"], "scenario.seed: must be in [0, 2^64 - 1]"),
    (None, ["--set", "scenario.start='yesterday'"], "scenario.start: expected a UTC ISO 8601 time"),
    (None, ["--set", "trajectory.colour=1"], "trajectory.colour: unknown key"),
    (None, ["--set", "trajectory.segment[9].kind='turn'"], "no index 9"),
    (None, ["--set", "trajectory.segment[1].accel_m_per_s2='fast'"], "expected a number"),
    (None, ["--set", "trajectory.origin.lat_deg=100.0"], "trajectory.origin.lat_deg: must be in [-90, 90]"),
    (None, ["--set", "gnss.elevation_mask_deg=89.9"], "gnss.elevation_mask_deg: no satellite"),
    (None, ["--set", "gnss.rate_hz=3.0"], "gnss.rate_hz: must divide trajectory.rate_hz"),
    (None, ["--set", "gnss.signals=['L9X']"], "gnss.signals"),
    (None, ["--set", "gnss.constellation[0].source='missing.rnx'"], "gnss.constellation[0].source"),
    (None, ["--set", "scenario.start='2001-01-01T00:00:00Z'"], "no satellite"),
    (None, ["--set", "imu.preset='no_such_imu'"], "imu.preset"),
    (None, ["--set", "imu.rate_hz=7.0"], "imu.rate_hz: must equal trajectory.rate_hz"),
    (None, ["--set", "novalue"], "--set: expected dotted.key=value"),
    (GOOD.replace("duration_s = 2.0\n\n[trajectory]", "duraton_s = 2.0\n\n[trajectory]"), [],
     "scenario.duration_s: missing required key (expected a number; found 'duraton_s'"),
    (GOOD.replace('name = "tiny"', 'name = "a b"'), [], "scenario.name: must be letters"),
    ("[scenario\nname = 1\n", [], "not valid TOML"),
    # a typo'd table is named itself, before the required keys it leaves missing (was "trajectory.rate_hz:
    # missing required key", or "known keys: gnss, scenario, trajectory" without imu and environment)
    (GOOD.replace("[trajectory]", "[trajectroy]"), [], "trajectroy: unknown key (did you mean 'trajectory'?)"),
    (GOOD + "\n[imus]\npreset = 'ideal'\n", [], "imus: unknown key (did you mean 'imu'?)"),
    (GOOD + "\n[enviroment]\n", [], "enviroment: unknown key (did you mean 'environment'?)"),
    (GOOD + GNSS.format(mask=10.0, source="nominal:gps") + GNSS.format(mask=10.0, source="nominal:gps")
     .replace("[gnss]\nrate_hz = 1.0\nelevation_mask_deg = 10.0\nsignals = [\"L1C\"]\n", ""), [],
     "satellites loaded twice"),
]


@pytest.mark.parametrize("text,extra,expect", RUN_CASES, ids=[str(i) for i in range(len(RUN_CASES))])
def test_run_bad_scenarios(tmp_path, text, extra, expect):
    scenario = "quickstart" if text is None else _scenario(tmp_path, text)
    assert_clean_error(["run", scenario, "-q", "-o", "out.h5", *extra], tmp_path, expect)


def test_run_directory_as_scenario(tmp_path):
    (tmp_path / "folder").mkdir()
    assert_clean_error(["run", "folder", "-q"], tmp_path, "is a directory, expected a scenario TOML file")


def test_run_of_a_simulated_file_names_it(tmp_path):
    """`simkit run out.h5` (a simulated file given for its scenario): one line saying what the file is, not a
    UTF-8 decoding error."""
    (tmp_path / "done.h5").write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(64))
    assert_clean_error(["run", "done.h5", "-q", "-o", "out.h5"], tmp_path,
                       "done.h5: is an HDF5 file (a simulated one?), expected a scenario TOML file")


def test_run_missing_scenario(tmp_path):
    assert_clean_error(["run", "nowhere.toml", "-q"], tmp_path, "no such scenario file")


@pytest.mark.parametrize("out,expect", [
    ("missing_dir/out.h5", "folder missing_dir does not exist"),
    (".", "is a directory"),
    ("s.toml", "is an input of this command"),
])
def test_run_bad_output_paths(tmp_path, out, expect):
    _scenario(tmp_path, GOOD)
    assert_clean_error(["run", "s.toml", "-q", "-o", out], tmp_path, expect)


def _foreign(path: Path) -> None:
    with h5py.File(path, "w") as f:
        f["x"] = 1


def _solved(path: Path) -> None:
    """A simkit file holding /solutions: results a re-run must not wipe."""
    import simkit
    from simkit.io import write_solution
    from simkit.solution import Solution

    simkit.run("quickstart", out=path, overrides=["scenario.duration_s=2"])
    write_solution(path, "mine", Solution(t=[0.0, 1.0], pos_ecef=[[6.4e6, 0, 0]] * 2))


@pytest.mark.parametrize("name, make, expect", [
    ("README.md", lambda p: p.write_text("# my notes\n"), "README.md: exists and is not a simkit file"),
    ("table.csv", lambda p: p.write_text("a,b\n1,2\n"), "table.csv: exists and is not a simkit file"),
    ("other.h5", _foreign, "other.h5: exists and is not a simkit file"),
    ("solved.h5", _solved, "solved.h5: exists and holds /solutions"),
])
def test_run_never_replaces_a_file_it_did_not_write(tmp_path, name, make, expect):
    """Regression: `run -o` used to overwrite any file silently; now only a simkit file without /solutions
    (what a run writes), unless --force."""
    make(tmp_path / name)
    before = digest(tmp_path / name)
    assert_clean_error(["run", "quickstart", "-q", "-o", name, "--set", "scenario.duration_s=2"], tmp_path, expect)
    assert digest(tmp_path / name) == before


@pytest.mark.parametrize("what", ["log", "navigation"])
def test_run_force_never_replaces_a_file_the_scenario_reads(tmp_path, what):
    """`--force` replaces a file a run did not write, but never one the run reads: its trajectory log or a
    constellation source (before, `run replay_drive.toml -o drive_1hz.nmea --force` overwrote the log)."""
    import shutil

    nav = ROOT / "simkit" / "data" / "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"
    shutil.copyfile(ROOT / "examples" / "drive_1hz.nmea", tmp_path / "drive.nmea")
    shutil.copyfile(nav, tmp_path / "nav.rnx.gz")
    text = (ROOT / "examples" / "replay_drive.toml").read_text().replace('"drive_1hz.nmea"', '"drive.nmea"')
    text = text.replace(f'"{nav.name}"', '"nav.rnx.gz"').replace("duration_s = 280.0", "duration_s = 5.0")
    name = _scenario(tmp_path, text)
    target = {"log": "drive.nmea", "navigation": "nav.rnx.gz"}[what]
    before = digest(tmp_path / target)
    assert_clean_error(["run", name, "-q", "-o", target, "--force"], tmp_path,
                       f"{target}: is an input of this command; choose another output name")
    assert digest(tmp_path / target) == before


def test_run_replaces_its_own_output_and_anything_with_force(tmp_path):
    import simkit

    out = simkit.run("quickstart", out=tmp_path / "q.h5", overrides=["scenario.duration_s=2"])
    simkit.run("quickstart", out=out, overrides=["scenario.duration_s=3"])  # a re-run of its own file
    with simkit.open(out) as ds:
        assert ds.duration_s("truth") == 3.0
    (tmp_path / "README.md").write_text("# notes\n")
    proc = run_cli(["run", "quickstart", "-q", "-o", "README.md", "--force", "--set", "scenario.duration_s=2"],
                   tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert h5py.is_hdf5(tmp_path / "README.md")


def test_rinex_name_stays_in_its_folder(tmp_path):
    """Regression: `rinex --name ../evil` wrote outside its folder."""
    import simkit

    simkit.run("quickstart", out=tmp_path / "q.h5", overrides=["scenario.duration_s=2"])
    for name in ("../evil", "sub/x", "..", ".hidden"):
        assert_clean_error(["rinex", "q.h5", "-o", "r", "--name", name], tmp_path, "--name: expected a plain")
    assert not list(tmp_path.parent.glob("evil*"))
    proc = run_cli(["rinex", "q.h5", "-o", "deep/er", "--name", "mine"], tmp_path)  # -o folders are created
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in (tmp_path / "deep" / "er").glob("mine_*")) == ["mine_ant0.rnx", "mine_ant1.rnx"]


def test_run_output_below_a_file(tmp_path):
    (tmp_path / "afile").write_text("x")
    assert_clean_error(["run", "quickstart", "-q", "-o", "afile/x.h5"], tmp_path, "afile/x.h5: afile is not a folder")


def test_run_unwritable_folder(tmp_path, monkeypatch):
    """A folder where the temporary file cannot be created (read-only, or root-owned for a user; CI runs as
    root, so the failure is injected at the probe) is refused before any simulation."""
    from simkit.io import output

    real_open = os.open

    def deny(path, *a, **k):
        if ".out.h5.tmp-" in str(path):
            raise PermissionError(13, "Permission denied")
        return real_open(path, *a, **k)

    monkeypatch.setattr(output.os, "open", deny)
    import simkit
    from simkit.errors import OutputError

    with pytest.raises(OutputError, match="cannot write in"):
        simkit.run("quickstart", out=tmp_path / "out.h5")
    assert not list(tmp_path.iterdir())


def test_inspect_and_rinex_bad_files(tmp_path):
    (tmp_path / "text.h5").write_text("hello")
    with h5py.File(tmp_path / "plain.h5", "w") as f:
        f["x"] = 1
    assert_clean_error(["inspect", "nope.h5"], tmp_path, "nope.h5: no such file")
    assert_clean_error(["inspect", "text.h5"], tmp_path, "not an HDF5 file")
    assert_clean_error(["inspect", "plain.h5"], tmp_path, "not a simkit file")
    assert_clean_error(["inspect", "."], tmp_path, "is a directory")
    assert_clean_error(["rinex", "plain.h5"], tmp_path, "not a simkit file")
    assert_clean_error(["rinex", "text.h5", "-o", "text.h5"], tmp_path, "exists and is not a folder")


def test_a_truncated_simkit_file_is_named_as_one(tmp_path):
    """A simkit file cut short (an interrupted copy) starts with the HDF5 signature: it is named as a damaged
    HDF5 file, not as "not an HDF5 file", by every reader."""
    import simkit

    whole = simkit.run(tmp_path / _scenario(tmp_path, GOOD), out=tmp_path / "t.h5")
    data = whole.read_bytes()
    (tmp_path / "cut.h5").write_bytes(data[: len(data) // 2])
    whole.unlink()
    for verb in (["inspect"], ["solve"], ["allan"], ["plot", "--out", "p"], ["score", "cut.h5"], ["validate"]):
        assert_clean_error([verb[0], "cut.h5", *verb[1:]], tmp_path,
                           "cut.h5: a damaged or truncated HDF5 file (an interrupted copy?)")


def test_rinex_of_a_file_without_gnss(tmp_path):
    import simkit

    simkit.run(tmp_path / _scenario(tmp_path, GOOD), out=tmp_path / "t.h5")
    assert_clean_error(["rinex", "t.h5", "-o", "rx"], tmp_path, "no /gnss group")


def test_unknown_command_and_option(tmp_path):
    assert_clean_error(["frobnicate"], tmp_path, "invalid choice")
    assert_clean_error(["run", "quickstart", "--colour"], tmp_path, "unrecognized arguments")


def test_run_takes_overrides_as_a_dict(tmp_path):
    """Regression: simkit.run(overrides=dict) failed with a command-line-worded error. A dict (dotted keys or
    nested tables) gives the same file as the --set strings."""
    import numpy as np

    import simkit
    from simkit.errors import ScenarioError

    a = simkit.run("quickstart", out=tmp_path / "a.h5", overrides=["scenario.duration_s=2", 'imu.preset="ideal"'])
    b = simkit.run("quickstart", out=tmp_path / "b.h5",
                   overrides={"scenario.duration_s": 2, "imu": {"preset": "ideal"}})
    with simkit.open(a) as da, simkit.open(b) as db:
        assert db.duration_s("truth") == 2.0 and db.group_attrs("imu", decode_json=True)["preset"] == "ideal"
        assert da.attrs["scenario_toml"] == db.attrs["scenario_toml"]
        for name, arr in da.datasets():
            assert np.array_equal(arr[:], db[name][:], equal_nan=arr.dtype.kind == "f"), name
    with pytest.raises(ScenarioError, match="scenario.duration_s: expected a TOML value"):
        simkit.run("quickstart", out=tmp_path / "c.h5", overrides={"scenario.duration_s": None})
    with pytest.raises(ScenarioError, match="overrides: expected a dict"):
        simkit.run("quickstart", out=tmp_path / "c.h5", overrides="scenario.duration_s=2")
    assert not (tmp_path / "c.h5").exists()


def test_an_error_inside_a_progress_bar_starts_its_own_line(tmp_path, monkeypatch):
    """Regression: errors were printed on the progress bar's line ("solve:  50%|#####  | 1/2 simkit solve:
    error: ..."). The bar is cleared first: the error line's text after the last carriage return is the error."""
    import contextlib
    import io

    from tqdm import tqdm

    import simkit.commands.inspect as inspect_cmd
    from simkit.cli import main
    from simkit.errors import DataFileError

    def stops_midway(args):
        bar = tqdm(total=2, desc="inspect", file=sys.stderr, leave=False, mininterval=0)
        bar.update()
        raise DataFileError(args.file, "broken halfway")

    monkeypatch.setattr(inspect_cmd, "run", stops_midway)
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        assert main(["inspect", "x.h5"]) == 2
    text = err.getvalue()
    assert "1/2" in text  # the bar was drawn
    last = text.rstrip("\n").split("\n")[-1]
    assert last.split("\r")[-1] == "simkit inspect: error: x.h5: broken halfway", repr(text)
