"""The lanes of a run (issue 25): the truth computed ahead on the lane's workers, the writer's bounded queue of chunks
being compressed, and the command's exit without the interpreter's teardown."""
import subprocess
import sys
import threading

import h5py
import numpy as np
import pytest
from truth_imu_scenario import truth_imu_toml

import simkit
from simkit import pipeline
from simkit.io import writer
from simkit.trajectory import generator


def _arrays(path):
    with h5py.File(path, "r") as f:
        out = {}
        f.visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
    return out


@pytest.mark.parametrize("threads", [2, 3])
def test_truth_ahead_and_small_queue_give_the_arrays_of_one_thread(tmp_path, monkeypatch, threads):
    """Many blocks (300 samples) with the truth two blocks ahead and a compression queue of a few chunks give the
    arrays of a run on one thread, in order, with one worker or two (the truth blocks then run on either)."""
    scenario = truth_imu_toml(tmp_path, 12.0)
    one = simkit.pipeline.run(scenario, out=tmp_path / "one.h5", block_samples=300, threads=1)
    held = []
    drain = writer.Writer._drain

    def watched(self, keep):
        drain(self, keep)
        held.append(self._held - keep)

    monkeypatch.setattr(writer, "IN_FLIGHT_BYTES", 3 * 8 * 8192)
    monkeypatch.setattr(writer, "CHUNK_ROWS", 512)
    monkeypatch.setattr(writer.Writer, "_drain", watched)
    many = simkit.pipeline.run(scenario, out=tmp_path / "many.h5", block_samples=300, threads=threads)
    a, b = _arrays(one), _arrays(many)
    assert a.keys() == b.keys() and len(a["truth/t"]) == 1201
    for k in a:
        assert np.array_equal(a[k], b[k]), k
    assert held and max(held) <= 0  # never more than the budget in flight after a drain


def test_a_failing_truth_block_stops_the_run_and_its_worker(tmp_path, monkeypatch):
    scenario = truth_imu_toml(tmp_path, 12.0)
    calls = []
    integrate = generator.Trajectory._integrate

    def failing(self, *args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise RuntimeError("third block")
        return integrate(self, *args, **kwargs)

    monkeypatch.setattr(generator.Trajectory, "_integrate", failing)
    with pytest.raises(RuntimeError, match="third block"):
        pipeline.run(scenario, out=tmp_path / "x.h5", block_samples=100, threads=2)
    assert len(calls) == 3                                  # nothing asked of the generator after its failure
    assert not [t for t in threading.enumerate() if t.name.startswith("simkit-lane")]
    assert not list(tmp_path.glob("*.h5*"))                 # no output, no temporary


def test_the_command_flushes_its_output_and_runs_atexit_handlers_before_it_ends(tmp_path):
    """simkit.cli.console (the ``simkit`` command, ``python -m simkit``) ends the process without the interpreter's
    teardown: what was printed and every atexit handler still come out, with the command's exit code."""
    scenario = truth_imu_toml(tmp_path, 2.0)
    code = ("import atexit, sys\nfrom simkit.cli import console\n"
            "atexit.register(lambda: print('atexit handler ran', flush=True))\n"
            f"sys.exit(console(['run', {str(scenario)!r}, '-o', {str(tmp_path / 'o.h5')!r}]))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines()[-2].startswith("wrote ") and out.stdout.splitlines()[-1] == "atexit handler ran"
    with h5py.File(tmp_path / "o.h5", "r") as f:
        assert f["imu/gyro"].shape == (201, 3)
    bad = subprocess.run([sys.executable, "-m", "simkit", "run", str(tmp_path / "missing.toml")],
                         capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and "missing.toml" in bad.stderr


def test_the_command_joins_a_thread_still_running_as_a_normal_exit_does(tmp_path):
    scenario = truth_imu_toml(tmp_path, 2.0)
    code = ("import sys, threading, time\nfrom simkit.cli import console\n"
            "threading.Thread(target=lambda: (time.sleep(1.0), print('thread done', flush=True))).start()\n"
            f"sys.exit(console(['run', {str(scenario)!r}, '-o', {str(tmp_path / 'o.h5')!r}, '-q']))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0 and out.stdout.splitlines()[-1] == "thread done"

