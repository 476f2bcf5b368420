"""simkit.heap at the size of a block of GNSS observables: freed blocks of arrays are reused instead of being
faulted in again, and the user's glibc tunables stand (glibc only)."""
import os
import platform
import subprocess
import sys

import pytest

from conftest import ROOT

# 30 blocks of 60 arrays of ~1 MB (a block of GNSS observables), minor page faults counted per block
CHILD = r"""
import resource, sys
import numpy as np

def faults():
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(30):
        block = [np.full((600, 3, 67), np.nan) for _ in range(60)]
        del block
    return (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before) / 30

plain = faults()   # before importing simkit, whose import can move glibc's dynamic mmap threshold (a freed mmap)
from simkit.heap import keep_freed_memory
changed = keep_freed_memory()
print(plain, faults(), changed, keep_freed_memory())
"""


def _run(**env):
    full = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_")}
    full.update(PYTHONPATH=str(ROOT), **env)
    out = subprocess.run([sys.executable, "-c", CHILD], env=full, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    plain, tuned, changed, again = out.stdout.split()
    return float(plain), float(tuned), changed == "True", again == "True"


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="the tuning applies to glibc only")
def test_freed_blocks_are_reused_without_page_faults():
    plain, tuned, changed, again = _run()
    pages = 60 * 600 * 3 * 67 * 8 / 4096          # pages of one block
    assert changed and again
    assert plain > 0.5 * pages                     # glibc as configured by default faults most of a block in again
    assert tuned < 0.05 * pages                    # now the block's pages are reused


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="the tuning applies to glibc only")
def test_the_users_malloc_tunables_stand():
    plain, tuned, changed, _ = _run(MALLOC_TRIM_THRESHOLD_="131072")
    assert not changed
    assert tuned > 0.5 * plain
