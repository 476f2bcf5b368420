"""The command line runs numpy's BLAS on one thread unless the user chose (simkit.cli.one_blas_thread)."""
import os
import subprocess
import sys

CHILD = r"""
import os, sys
import simkit.cli
chosen = simkit.cli.one_blas_thread()
import numpy
numpy.ones((64, 64)) @ numpy.ones((64, 64))
print(chosen, os.environ.get("OPENBLAS_NUM_THREADS"), len(os.listdir("/proc/self/task")))
"""


def child(env_value=None, numpy_first=False):
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
                                                              "MKL_NUM_THREADS")}
    if env_value is not None:
        env["OPENBLAS_NUM_THREADS"] = env_value
    code = ("import numpy\n" if numpy_first else "") + CHILD
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    chosen, value, tasks = out.stdout.split()
    return chosen == "True", value, int(tasks)


def test_one_thread_when_the_user_did_not_choose():
    chosen, value, tasks = child()
    assert chosen and value == "1"
    assert tasks == child("1")[2]          # as many threads as with the variable set by hand: no BLAS workers


def test_the_users_choice_stands():
    assert child("2")[:2] == (False, "2")


def test_too_late_once_numpy_is_loaded():
    chosen, value, _ = child(numpy_first=True)
    assert not chosen and value == "None"
