"""The C heap of a simkit process: freed memory kept for the next block instead of being returned to the system.

A run allocates and frees the same MB-sized arrays block after block (a block of GNSS observables holds some sixty
(M, A, S) float64 arrays of ~1 MB and as many temporaries; a truth + IMU block a few 8 MB series). glibc gives the
top of its heap back to the kernel once more than its trim threshold is free (a dynamic threshold of about twice
the largest freed size), and serves large arrays from separate mappings it unmaps on free, so every block faults
its pages in again: a fifth of the CPU of the 24 h observables benchmark (2 h: 288 k against 58 k minor faults,
3.02 against 2.42 s) and 81 k against 48 k faults for a truth + IMU run of 600 s at 1 kHz.

:func:`keep_freed_memory` raises the trim threshold and fixes the mmap threshold at glibc's largest (32 MB on
64-bit), above which arrays are still mapped one by one. The resident size then stays at its peak instead of
following it down; the peak itself is unchanged. :func:`simkit.pipeline.run` calls it (the command line and the
Python API alike); the user's own glibc tunables (``MALLOC_TRIM_THRESHOLD_``, ``MALLOC_MMAP_THRESHOLD_``) stand,
except in a campaign worker, whose nanny set them (:func:`simkit.campaign.task.tune_worker_process`). A no-op on
other C libraries.
"""
from __future__ import annotations

import os
import platform

TRIM_BYTES = 512 << 20      # freed heap kept by the process before glibc trims it
MMAP_BYTES = 32 << 20       # glibc's largest mmap threshold on 64-bit systems (larger values are refused)
M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3   # mallopt parameters (malloc.h)
TUNABLES = ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_")


def keep_freed_memory(trim_bytes: int = TRIM_BYTES, mmap_bytes: int = MMAP_BYTES, override_env: bool = False) -> bool:
    """Keep up to ``trim_bytes`` of freed heap for reuse and serve arrays below ``mmap_bytes`` from the heap.
    Returns whether glibc took both settings (False on other C libraries, and when the environment sets glibc's
    tunables and ``override_env`` is False)."""
    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        return False
    if not override_env and any(k in os.environ for k in TUNABLES):
        return False
    import ctypes

    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return bool(mallopt(M_TRIM_THRESHOLD, int(trim_bytes))) & bool(mallopt(M_MMAP_THRESHOLD, int(mmap_bytes)))
