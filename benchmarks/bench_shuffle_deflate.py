"""Benchmark: the writer's chunk encoding on the chunks of the truth + IMU run of issue 25 (600 s at 1 kHz, STIM300):
HDF5's shuffle + deflate of the whole chunk (ISA-L level 1, the encoding before the third round) against
:func:`simkit.io.shuffle_deflate.shuffle_deflate` (byte planes that do not compress stored in the stream), over
every full chunk of the series the writer compresses (its first chunk deflates to <= 80 %): thread CPU seconds
(best of ``--repeat``) and bytes. Every encoded chunk is checked to inflate to the shuffled bytes.

    python benchmarks/bench_shuffle_deflate.py [--seconds 600] [--repeat 5]
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
import zlib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # this checkout first

import bench_truth_imu  # noqa: E402

from simkit import pipeline  # noqa: E402
from simkit.io import shuffle_deflate as sd  # noqa: E402
from simkit.io.writer import CHUNK_ROWS, COMPRESS_MAX_RATIO  # noqa: E402
from simkit.scenario import load  # noqa: E402


def chunks(seconds: float) -> dict[str, list[np.ndarray]]:
    """The full chunks of every series of the run, by dataset path."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "s.toml"
        path.write_text(bench_truth_imu.scenario(seconds, 1000.0))
        stages = pipeline.build(load(path, []))
    out: dict[str, list[np.ndarray]] = {}
    for truth in stages.trajectory.blocks(block_samples=CHUNK_ROWS):
        if len(truth.t) < CHUNK_ROWS:
            break
        rows = pipeline._rows("truth", truth)
        rows.update(pipeline._imu_rows(truth.t, stages.imu.process(truth.t, truth.omega_ib_b, truth.f_ib_b)))
        for name, data in rows.items():
            out.setdefault(name, []).append(np.ascontiguousarray(data))
    return out


def whole(chunk: np.ndarray) -> bytes:
    """Shuffle + deflate of the whole chunk (the encoding before the third round)."""
    return sd.deflate.compress(sd.planes(chunk), sd.LEVEL)


def measure(series: dict[str, list[np.ndarray]], encode, repeat: int) -> tuple[float, int]:
    best, size = float("inf"), 0
    for _ in range(repeat):
        c = time.thread_time()
        size = sum(len(encode(chunk)) for cs in series.values() for chunk in cs)
        best = min(best, time.thread_time() - c)
    return best, size


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=600.0)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    every = chunks(args.seconds)
    series = {k: cs for k, cs in every.items() if len(whole(cs[0])) <= COMPRESS_MAX_RATIO * cs[0].nbytes}
    for cs in series.values():
        for chunk in cs:
            assert zlib.decompress(sd.shuffle_deflate(chunk)) == sd.planes(chunk).tobytes()
    raw = sum(c.nbytes for cs in series.values() for c in cs)
    print(f"{len(series)} compressed series, {sum(len(cs) for cs in series.values())} full chunks, {raw / 1e6:.0f} MB "
          f"({sd.deflate.__name__})")
    for name, fn in (("whole chunk deflated", whole), ("incompressible planes stored", sd.shuffle_deflate)):
        cpu, size = measure(series, fn, args.repeat)
        print(f"  {name:<30} {cpu:.3f} s CPU, {size / 1e6:.1f} MB ({size / raw:.3f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
