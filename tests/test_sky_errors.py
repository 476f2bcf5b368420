"""``simkit sky`` with bad input: one line on stderr, exit 2, no traceback, nothing left on disk; empty skies name
the source and the span it covers; a closed output pipe ends quietly."""
import os
import subprocess
import sys
from argparse import Namespace

import pytest

from cli_errors import ROOT, assert_clean_error
from conftest import DATA

SITE = ["--lat", "34.25", "--lon", "108.95", "--start", "2026-04-27T06:00:00Z"]
BRDM = "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"
# first GPS toe - 2 h .. last Galileo toe + 4 h (a Galileo record holds for 4 h after its toe)
BRDM_SPAN = "covers 2026-04-26 21:59:42 UTC to 2026-04-28 03:49:42 UTC"
YUMA = str(DATA / "yuma" / "almanac.yuma.week0149.405504.txt")     # toa 2022-02-17 16:38:24 GPST

BAD = [
    (["--hours", "-1"], "--hours: found -1"),
    (["--hours", "nan"], "--hours: found nan"),
    (["--hours", "1e9"], "pass --force"),
    (["--step", "0"], "--step: found 0"),
    (["--step", "-5"], "--step: found -5"),
    (["--lat", "100"], "--lat: found 100; expected -90 to 90 deg"),
    (["--lat", "-90.5"], "--lat: found -90.5"),
    (["--lon", "400"], "--lon: found 400"),
    (["--lon", "inf"], "--lon: found inf"),
    (["--height", "-20000"], "--height: found -20000"),
    (["--height", "1e9"], "--height: found 1e+09"),
    (["--mask", "95"], "--mask: found 95"),
    (["--validity-days", "0"], "--validity-days: found 0"),
    (["--start", "2026-13-01"], "--start: expected an ISO 8601 UTC time"),
    (["--start", "1975-01-01T00:00:00Z"], "before the GPS epoch 1980-01-06"),
    (["--plot", "no/such/folder/sky.png"], "--plot: folder 'no/such/folder' does not exist"),
    (["--plot", "sky.xyz"], "--plot: sky.xyz: unknown image format 'xyz'"),
    (["no_such_nav_file.rnx"], "no_such_nav_file.rnx: no such file"),
    (["nominal:galileo"], "expected one of nominal:gps"),
]


@pytest.mark.parametrize("extra, expect", BAD, ids=[" ".join(a) for a, _ in BAD])
def test_bad_input_is_one_line_and_exit_2(tmp_path, extra, expect):
    args = ["sky", *SITE, *extra] if extra[0].startswith("--") else ["sky", extra[0], *SITE]
    # a later --start replaces SITE's; a later --lat / --lon too (argparse keeps the last)
    assert_clean_error(args, tmp_path, expect=expect)


EMPTY = [
    ([BRDM, "--start", "2026-05-10T00:00:00Z"],
     f"{BRDM}: no satellite has a state from 2026-05-10 00:00:00 UTC to 2026-05-10 02:00:00 UTC; the source "
     f"{BRDM_SPAN}"),
    ([BRDM, "--mask", "89.99", "--plot", "sky.png"], f"is at or above 89.99 deg at any step from 2026-04-27 "
                                                     f"06:00:00 UTC to 2026-04-27 08:00:00 UTC (the source {BRDM_SPAN})"),
    (["nominal:gps", "--mask", "89.9"], "no satellite of nominal:gps is at or above 89.9 deg at any step from "
                                        "2026-04-27 06:00:00 UTC to 2026-04-27 08:00:00 UTC (the source covers "
                                        "every epoch)"),
    ([YUMA, "--start", "2022-03-20T00:00:00Z"],
     "the source covers 2022-02-10 16:38:06 UTC to 2022-02-24 16:38:06 UTC"),  # toa +- 7 days, UTC = GPST - 18 s
]


@pytest.mark.parametrize("extra, expect", EMPTY, ids=["uncovered start", "mask 89.99 (and no plot left)",
                                                      "nominal mask", "almanac a month late"])
def test_an_empty_sky_names_the_source_and_its_span(tmp_path, extra, expect):
    assert_clean_error(["sky", extra[0], *SITE, *extra[1:]], tmp_path, expect=expect)


def test_plot_without_matplotlib_names_the_plot_extra(tmp_path, monkeypatch):
    shadow = tmp_path / "shadow" / "matplotlib"
    shadow.mkdir(parents=True)
    (shadow / "__init__.py").write_text("raise ImportError(\"No module named 'matplotlib'\")\n")
    monkeypatch.setenv("PYTHONPATH", str(shadow.parent))
    work = tmp_path / "work"
    work.mkdir()
    line = assert_clean_error(["sky", "nominal:gps", *SITE, "--plot", "sky.png"], work,
                              expect="--plot: needs matplotlib", isolated=True)
    assert "simkit[plot]" in line


def test_output_into_a_closed_pipe_ends_quietly(tmp_path):
    """30,001 lines (~1.8 MB, far beyond a pipe buffer): the reader takes one line and closes."""
    env_path = str(ROOT)
    proc = subprocess.Popen([sys.executable, "-m", "simkit", "sky", "nominal:gps", *SITE, "--hours", "500",
                             "--step", "60"], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            env=dict(os.environ, PYTHONPATH=env_path))
    first = proc.stdout.readline()
    proc.stdout.close()
    err = proc.stderr.read().decode()
    proc.wait(timeout=120)
    assert first.startswith(b"nominal:gps: 24 satellites")
    assert proc.returncode == 0 and err == "", err


def test_force_lifts_the_memory_limit_and_a_normal_span_passes():
    from simkit.commands import sky

    big = Namespace(hours=1e4, step=1.0, force=False)
    with pytest.raises(Exception, match="--hours: 10000 h at --step 1 s is 36,000,001 epochs"):
        sky._step_count(big, 67)
    assert sky._step_count(Namespace(hours=1e4, step=1.0, force=True), 67) == 36_000_001
    assert sky._step_count(Namespace(hours=2.0, step=600.0, force=False), 67) == 13
