"""The process's memory allocator, tuned for block-wise array work.

A block of GNSS observables holds some sixty (M, A, S) float64 arrays of about 1 MB each (600 epochs, 3 antennas,
67 satellites) and as many temporaries, all freed when the block is written. glibc's malloc serves such sizes from
the heap, and when they are freed together it gives the top of the heap back to the kernel (``M_TRIM_THRESHOLD``,
which its dynamic rule keeps at twice the largest size freed, about 2 MB here), so the next block faults every page
in again: a fifth of the CPU time of the 24 h benchmark went to zeroing fresh pages (docs/benchmarks.md).

:func:`retain_freed_memory` raises the trim threshold, so freed blocks stay in the process for the next one (the
resident size stays at its peak instead of following it down; the peak itself is unchanged), and fixes the mmap
threshold at glibc's largest heap size (32 MB on 64-bit), above which arrays are still mapped and unmapped one by
one. It changes nothing on other C libraries, and nothing when the user set ``MALLOC_TRIM_THRESHOLD_`` or
``MALLOC_MMAP_THRESHOLD_`` (glibc's own tunables, which then stand).
"""
from __future__ import annotations

import ctypes
import os
import platform

TRIM_THRESHOLD = 512 << 20   # bytes of freed heap kept by the process before glibc trims it
MMAP_THRESHOLD = 32 << 20    # glibc's largest (HEAP_MAX_SIZE / 2 on 64-bit): bigger arrays are mapped
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3   # mallopt parameters (malloc.h)
_done: list[bool] = []


def retain_freed_memory() -> bool:
    """Keep freed heap memory for reuse (see the module docstring); once per process. True when glibc's
    settings were changed (now or by an earlier call)."""
    if _done:
        return _done[0]
    ok = False
    if (platform.system() == "Linux" and platform.libc_ver()[0] == "glibc"
            and not any(k in os.environ for k in ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_"))):
        try:
            libc = ctypes.CDLL("libc.so.6")
            ok = bool(libc.mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)) and \
                bool(libc.mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD))
        except (OSError, AttributeError):
            ok = False
    _done.append(ok)
    return ok
