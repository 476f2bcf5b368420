"""``simkit.heap.keep_freed_memory`` (called by ``simkit.run``): blocks of MB-sized arrays allocated and
freed again and again stop faulting their pages in after the first round (glibc; elsewhere it reports False)."""
import os
import subprocess
import sys

import pytest

CHILD = r"""
import resource, sys
import numpy as np
from simkit.heap import keep_freed_memory
kept = keep_freed_memory() if sys.argv[1] == "1" else None
arrs = [np.ones(1 << 18) for _ in range(10)]; del arrs            # ten 2 MB arrays, as a run's block
f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(20):
    arrs = [np.ones(1 << 18) for _ in range(10)]; del arrs
print(kept, resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt: Linux only")
def test_freed_blocks_are_reused_without_page_faults():
    def faults(keep: str):
        # without glibc tunables in the environment (a Dask cluster started earlier in this process sets them)
        env = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_")}
        out = subprocess.run([sys.executable, "-c", CHILD, keep], env=env, capture_output=True, text=True, check=True)
        kept, count = out.stdout.split()
        return kept, int(count)

    default, kept = faults("0"), faults("1")
    assert kept[0] == "True"
    assert default[1] > 20 * 512               # glibc's defaults: at least a 2 MB array per round faults in again
    #                                            (35,000-100,000 of the 102,400 pages measured: its thresholds adapt)
    assert kept[1] < 1000                      # kept: the heap serves them from pages already mapped
