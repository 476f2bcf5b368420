"""The C heap of a simkit command's own process: freed memory kept for the next block, not returned to the system.

A run allocates and frees the same MB-sized arrays block after block. glibc gives the top of its heap back to the
system once more than its trim threshold is free, and serves large arrays from separate mappings it unmaps on
free, so every block faults its pages in again: 100,000 page faults and ~0.1 s of system time for a truth + IMU
run of 600 s at 1 kHz, about half of them avoidable (measured with ``/usr/bin/time -v``). Called by the command
line only: a library must not change its host's allocator. A no-op where glibc's ``mallopt`` is missing.
"""
from __future__ import annotations

import sys

M_TRIM_THRESHOLD = -1
M_MMAP_THRESHOLD = -3
MMAP_THRESHOLD_MAX = 32 * 2**20  # glibc's ceiling on 64-bit systems (larger values are refused)


def keep_freed_memory(trim_bytes: int = 2**30, mmap_bytes: int = MMAP_THRESHOLD_MAX) -> bool:
    """Raise glibc's trim threshold to ``trim_bytes`` and serve arrays below ``mmap_bytes`` from the heap; returns
    whether glibc took both settings."""
    if not sys.platform.startswith("linux"):
        return False
    import ctypes

    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return bool(mallopt(M_TRIM_THRESHOLD, trim_bytes)) & bool(mallopt(M_MMAP_THRESHOLD, mmap_bytes))
