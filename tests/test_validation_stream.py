"""`simkit validate` on a scenario streams the sky geometry in blocks: the same arrays as one block, and memory
bounded by what is kept (lines of sight, elevations, visibility) instead of the whole light-time solution."""
import tracemalloc

import numpy as np

from simkit.scenario import load
from simkit.validation import geometry

OVERRIDES = ["scenario.duration_s=600", "trajectory.rate_hz=1.0"]


def test_streamed_geometry_equals_one_block():
    sc = load("xian_static_bds", OVERRIDES)
    whole = geometry.from_scenario(sc, block_epochs=10**6)
    for block in (1, 37, 600):
        part = geometry.from_scenario(sc, block_epochs=block)
        for name in ("t", "los_b", "elevation", "visible"):
            a, b = getattr(whole, name), getattr(part, name)
            assert a.shape == b.shape and np.array_equal(a, b, equal_nan=True), (block, name)
        assert part.sat_ids == whole.sat_ids


def _peak_bytes(sc, block_epochs):
    tracemalloc.start()
    try:
        geo = geometry.from_scenario(sc, block_epochs=block_epochs)
        return tracemalloc.get_traced_memory()[1], geo
    finally:
        tracemalloc.stop()


def test_geometry_memory_is_what_is_kept_plus_one_block():
    """Peak traced memory over a 2 h run (7201 epochs) in blocks of 300: at most the kept arrays plus one
    block's light-time geometry (300 of the 7201 epochs, counted as 1 kB per satellite-epoch); the unstreamed
    path needed several times the kept arrays."""
    sc = load("xian_static_bds", ["scenario.duration_s=7200", "trajectory.rate_hz=1.0"])
    geometry.from_scenario(load("xian_static_bds", OVERRIDES), block_epochs=100)   # imports and caches warm
    peak, geo = _peak_bytes(sc, 300)
    kept = geo.t.nbytes + geo.los_b.nbytes + geo.elevation.nbytes + geo.visible.nbytes
    block = 300 * len(geo.sat_ids) * 1024
    print(f"\npeak {peak / 1e6:.1f} MB, kept {kept / 1e6:.1f} MB, one block {block / 1e6:.1f} MB")
    assert peak < kept + block
    whole, _ = _peak_bytes(sc, 10**6)
    print(f"unstreamed peak {whole / 1e6:.1f} MB")
    assert whole > 2 * peak   # the bound above is one that the unstreamed path breaks
