"""Timing shared by the benchmarks (imported as ``timing``: the script's folder is on sys.path)."""
from __future__ import annotations

import time


def best_of(fn, repeat: int = 3) -> float:
    """Shortest wall time (s) of ``repeat`` calls of ``fn()``: the least disturbed by other load."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def print_table(headers, rows) -> None:
    """Print rows of strings as an aligned text table under ``headers``."""
    widths = [max(len(str(x)) for x in col) for col in zip(headers, *rows)]
    for row in (headers, *rows):
        print("  ".join(str(x).ljust(w) for x, w in zip(row, widths)).rstrip())


def ab(trees, probe: str, columns, rounds: int = 3, extra_path=None, own_cache: bool = False):
    """A/B timing between checkouts (e.g. before and after a change), the runner of bench_kf_ab and bench_lambda_ab.

    Each tree in ``trees`` runs ``probe`` (Python source; ``sys.argv[1]`` is the tree, ``sys.argv[2]`` is
    ``extra_path``) in its own interpreter, alternating, ``rounds`` times; the probe prints its figures on one
    line, one per name in ``columns``. With ``own_cache`` each tree gets its own ``NUMBA_CACHE_DIR``, compiled by a
    first, untimed run. Prints the table as it goes and returns [(tree, [figures])]."""
    import os
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        caches = {tree: Path(tmp) / f"tree{i}" for i, tree in enumerate(trees)}

        def run(tree):
            env = dict(os.environ, NUMBA_CACHE_DIR=str(caches[tree])) if own_cache else None
            out = subprocess.run([sys.executable, "-c", probe, str(Path(tree).resolve()), str(extra_path or "")],
                                 env=env, capture_output=True, text=True, check=True)
            return out.stdout.split()

        if own_cache:
            for tree in trees:
                run(tree)  # compiles into the tree's cache
        print(f"{'tree':<30} " + " ".join(f"{c:>11}" for c in columns))
        for _ in range(rounds):
            for tree in trees:
                figures = run(tree)
                rows.append((str(tree), figures))
                print(f"{str(tree):<30} " + " ".join(f"{v:>11}" for v in figures))
    print(f"load average (1 min): {os.getloadavg()[0]:.1f}")
    return rows


def ab_main(doc: str, probe: str, columns, argv=None, extra_path=None, own_cache: bool = False) -> int:
    """The command line of an A/B benchmark (``A B [--rounds N]``) around :func:`ab`; ``doc`` its description."""
    import argparse

    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args(argv)
    ab([args.a, args.b], probe, columns, args.rounds, extra_path, own_cache=own_cache)
    return 0
