"""``simkit compile``: compile the numba kernels a first run needs, once, into the prepared cache (simkit/_jit).

Run it right after installing (a container or cluster image: before making the install read-only); every later
process, whatever its ``NUMBA_CACHE_DIR``, then loads the kernels instead of compiling them (docs/cold_start.md).
"""
from __future__ import annotations

import sys
import time


def add_parser(sub):
    p = sub.add_parser("compile", help="compile the numba kernels once, into the install (first runs then load them)",
                       description="Compile the numba kernels that `simkit run` and `simkit solve` use (several "
                                   "minutes of CPU) and store them in the install's prepared cache, which seeds "
                                   "numba's cache in every later process (docs/cold_start.md).")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    return p


def run(args) -> int:
    from ..api import prepare_cache

    if not args.quiet:
        print("simkit compile: compiling the kernels (several minutes of CPU, once per install) ...", file=sys.stderr)
    t = time.perf_counter()
    path, count = prepare_cache(progress=False)
    if not args.quiet:
        print(f"simkit compile: {count} files in {path} ({time.perf_counter() - t:.0f} s)", file=sys.stderr)
    return 0
