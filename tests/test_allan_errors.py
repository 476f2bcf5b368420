"""``simkit allan`` on bad input: one clean line, exit 2, nothing on disk; a closed pipe is not an error; and on a
good file the fitted white-noise coefficient matches the density the record was drawn with (N^2 / tau)."""
import json
import os
import subprocess
import sys

import h5py
import numpy as np
import pytest

from cli_errors import ROOT, assert_clean_error, digest, run_cli

RATE = 100.0
N_WHITE = 1e-3   # rad/s^0.5: white rate noise of two-sided PSD N^2, sample std N / sqrt(dt)


def _simkit_file(path, n=20_000, imu=True, t=None, gyro_shape=None, gyro=None):
    """A minimal schema-v1 file: /imu/t, /imu/gyro, /imu/accel (white noise), written with plain h5py."""
    rng = np.random.default_rng(1)
    with h5py.File(path, "w") as h5:
        h5.attrs["schema_version"] = 1
        h5.create_dataset("truth/t", data=np.arange(n) / RATE)
        if imu:
            h5.create_dataset("imu/t", data=np.arange(n) / RATE if t is None else t)
            shape = gyro_shape or (n, 3)
            h5.create_dataset("imu/gyro", data=N_WHITE * np.sqrt(RATE) * rng.standard_normal(shape)
                              if gyro is None else gyro)
            h5.create_dataset("imu/accel", data=rng.standard_normal((n, 3)))
            h5["imu"].attrs["preset"] = "test"
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("allan_inputs")
    (d / "notes.txt").write_text("not hdf5\n")
    with h5py.File(d / "foreign.h5", "w") as h5:
        h5.create_dataset("x", data=[1.0, 2.0])
    return {"good": _simkit_file(d / "good.h5"), "short": _simkit_file(d / "short.h5", n=8),
            "mid": _simkit_file(d / "mid.h5", n=20), "noimu": _simkit_file(d / "noimu.h5", imu=False),
            "badshape": _simkit_file(d / "badshape.h5", n=100, gyro_shape=(100, 2)),
            "flat": _simkit_file(d / "flat.h5", n=1000, gyro=np.zeros((1000, 3))),
            "stuck": _simkit_file(d / "stuck.h5", n=100, t=np.zeros(100)),
            "text": d / "notes.txt", "foreign": d / "foreign.h5", "dir": d}


CASES = [
    (lambda f: [str(f["dir"] / "missing.h5")], "no such file"),
    (lambda f: [str(f["dir"])], "is a directory"),
    (lambda f: [str(f["text"])], "not an HDF5 file"),
    (lambda f: [str(f["foreign"])], "not a simkit file"),
    (lambda f: [str(f["noimu"])], "no /imu/t and /imu/gyro"),
    (lambda f: [str(f["badshape"])], "must be (N, 3)"),
    (lambda f: [str(f["short"])], "record too short: 8 IMU samples"),
    (lambda f: [str(f["mid"]), "--gauss-markov", "3"], "20 IMU samples give 7 Allan points, fitting 5 IEEE terms + 3 Gauss-Markov needs at least 8"),
    (lambda f: [str(f["good"]), "--gauss-markov", "-1"], "--gauss-markov: must be >= 0"),
    (lambda f: [str(f["good"]), "--gauss-markov", "40"], "--gauss-markov: at most 3"),
    (lambda f: [str(f["flat"])], "no noise to analyse"),
    (lambda f: [str(f["stuck"])], "/imu/t does not increase"),
    (lambda f: [str(f["good"]), "--json", "nodir/out.json"], "--json: nodir/out.json: folder nodir does not exist"),
    (lambda f: [str(f["good"]), "--plot", "nodir/adev.png"], "--plot: nodir/adev.png: folder nodir does not"),
    # the output is never the file being read
    (lambda f: [str(f["good"]), "--json", str(f["good"])], "is an input of this command"),
    (lambda f: [str(f["good"]), "--plot", str(f["good"])], "is an input of this command"),
    (lambda f: [str(f["good"]), "--json", "."], "is a directory"),
    (lambda f: [str(f["good"]), "--plot", "adev.notaformat"], "adev.notaformat: unknown image format"),
]


@pytest.mark.parametrize("make_args,expect", CASES)
def test_bad_input_is_one_line(files, tmp_path, make_args, expect):
    before = digest(files["good"])
    assert_clean_error(["allan", *make_args(files)], tmp_path, expect=expect)
    assert digest(files["good"]) == before


def test_output_checks_come_before_any_work(files, tmp_path):
    """A missing output directory is reported even for an input that would fail later (checked first)."""
    assert_clean_error(["allan", str(files["short"]), "--json", "nodir/x.json"], tmp_path, expect="--json")


def test_plot_without_matplotlib_names_the_extra(files, tmp_path, monkeypatch):
    blocker = tmp_path.parent / f"{tmp_path.name}_no_mpl"
    (blocker / "matplotlib").mkdir(parents=True)
    (blocker / "matplotlib" / "__init__.py").write_text("raise ImportError('matplotlib is not installed')\n")
    monkeypatch.setenv("PYTHONPATH", str(blocker))
    assert_clean_error(["allan", str(files["good"]), "--plot", "adev.png"], tmp_path, expect="'simkit[plot]'",
                       isolated=True)


def test_closed_pipe_is_quiet(files, tmp_path):
    """``simkit allan f.h5 | head -0``: the reader is gone before the first write; no BrokenPipeError, and the
    JSON asked for is still written."""
    read_end, write_end = os.pipe()
    os.close(read_end)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.run([sys.executable, "-m", "simkit", "allan", str(files["good"]), "--json", "fit.json"],
                          cwd=tmp_path, env=env, stdout=write_end, stderr=subprocess.PIPE, text=True, timeout=120)
    os.close(write_end)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert json.loads((tmp_path / "fit.json").read_text())["sensor"] == "gyro"


def test_white_noise_fit_matches_its_density(files, tmp_path):
    proc = run_cli(["allan", str(files["good"]), "--json", "fit.json"], tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "preset test" in proc.stdout.splitlines()[0]
    fit = json.loads((tmp_path / "fit.json").read_text())["fit"]
    for axis in "xyz":
        assert fit[axis]["N"] == pytest.approx(N_WHITE, rel=0.05)
