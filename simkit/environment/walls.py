"""Vertical building walls in the local plane of the trajectory's origin, and a uniform grid over them.

A wall is a vertical rectangle standing on the horizontal segment A -> B (east, north in metres, in the ENU frame
of the trajectory origin), reaching from below every antenna up to ``top`` m above the origin (the IMU centre at
t = 0). Walls come from parametric street canyons (:func:`canyon_walls`) or from building footprints
(:func:`footprint_walls`). The grid lists, per square cell, the walls whose segment crosses it (an exact
supercover, column by column), so a ray or a neighbourhood query visits only the walls near it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_MAX_CELLS = 4_000_000


@dataclass(frozen=True)
class Walls:
    """W walls: segment ends ``a``, ``b`` (W, 2) m (east, north) and top heights ``top`` (W,) m above the
    origin."""

    a: np.ndarray
    b: np.ndarray
    top: np.ndarray

    @staticmethod
    def concat(parts) -> "Walls":
        parts = [p for p in parts if p.top.size]
        if not parts:
            return Walls(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0))
        return Walls(np.concatenate([p.a for p in parts]), np.concatenate([p.b for p in parts]),
                     np.concatenate([p.top for p in parts]))


def canyon_walls(centre_en, azimuth_rad: float, width_m: float, length_m: float, left_height_m: float,
                 right_height_m: float) -> Walls:
    """The two walls of a straight street canyon: street axis through ``centre_en`` (2,) m along azimuth
    ``azimuth_rad`` (clockwise from north), walls ``width_m / 2`` either side over ``length_m`` centred on
    ``centre_en``. Left is the wall on the left when looking along the azimuth. Walls of height <= 0 are left
    out (nothing above the reference point)."""
    axis = np.array([np.sin(azimuth_rad), np.cos(azimuth_rad)])
    left = np.array([-axis[1], axis[0]])                       # axis turned 90 deg anticlockwise
    c = np.asarray(centre_en, dtype=float)
    half = 0.5 * length_m * axis
    out = []
    for side, h in ((1.0, left_height_m), (-1.0, right_height_m)):
        if h > 0:
            off = c + side * 0.5 * width_m * left
            out.append(Walls((off - half)[None], (off + half)[None], np.array([float(h)])))
    return Walls.concat(out)


def footprint_walls(rings_en, heights) -> Walls:
    """Walls of building footprints: each ring (K, 2) m (east, north; closed or not) gives one wall per edge, at
    the building's height (m above the origin). Zero-length edges are dropped."""
    a, b, top = [], [], []
    for ring, h in zip(rings_en, heights):
        ring = np.asarray(ring, dtype=float)
        if np.allclose(ring[0], ring[-1]):
            ring = ring[:-1]
        nxt = np.roll(ring, -1, axis=0)
        keep = np.hypot(*(nxt - ring).T) > 1e-6
        a.append(ring[keep])
        b.append(nxt[keep])
        top.append(np.full(int(keep.sum()), float(h)))
    if not a:
        return Walls(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0))
    return Walls(np.concatenate(a), np.concatenate(b), np.concatenate(top))


@dataclass(frozen=True)
class Grid:
    """Uniform grid over the walls: lower-left corner ``x0``, ``y0`` m, square ``cell`` m, ``nx`` x ``ny`` cells;
    the walls of cell (ix, iy) are ``walls[start[k]:start[k + 1]]`` with k = ix * ny + iy."""

    x0: float
    y0: float
    cell: float
    nx: int
    ny: int
    start: np.ndarray
    walls: np.ndarray


def build_grid(walls: Walls, cell_m: float) -> Grid:
    """The grid of ``walls`` with cells of ``cell_m`` (enlarged if the walls' extent would need more than four
    million cells)."""
    if walls.top.size == 0:
        return Grid(0.0, 0.0, 1.0, 1, 1, np.zeros(2, dtype=np.int64), np.zeros(0, dtype=np.int64))
    pts = np.concatenate([walls.a, walls.b])
    lo, hi = pts.min(axis=0) - 1.0, pts.max(axis=0) + 1.0
    span = hi - lo
    cell = max(float(cell_m), float(np.sqrt(span[0] * span[1] / _MAX_CELLS)))
    nx, ny = (int(n) for n in np.maximum(np.ceil(span / cell), 1))
    cells, owners = [], []
    for w in range(walls.top.size):
        k = _supercover(walls.a[w], walls.b[w], lo, cell, nx, ny)
        cells.append(k)
        owners.append(np.full(k.size, w, dtype=np.int64))
    cells, owners = np.concatenate(cells), np.concatenate(owners)
    order = np.lexsort((owners, cells))
    cells, owners = cells[order], owners[order]
    start = np.searchsorted(cells, np.arange(nx * ny + 1)).astype(np.int64)
    return Grid(float(lo[0]), float(lo[1]), cell, nx, ny, start, owners)


def _supercover(a, b, lo, cell, nx, ny) -> np.ndarray:
    """Flat indices of every cell the segment a -> b touches: per column, the rows between the segment's
    heights at the column's edges."""
    (xa, ya), (xb, yb) = (np.asarray(a) - lo) / cell, (np.asarray(b) - lo) / cell
    if xa > xb:
        xa, ya, xb, yb = xb, yb, xa, ya
    i0, i1 = int(np.clip(np.floor(xa), 0, nx - 1)), int(np.clip(np.floor(xb), 0, nx - 1))
    cols = np.arange(i0, i1 + 1)
    xl, xr = np.maximum(cols, xa), np.minimum(cols + 1, xb)
    if xb > xa:
        yl, yr = ya + (xl - xa) * (yb - ya) / (xb - xa), ya + (xr - xa) * (yb - ya) / (xb - xa)
    else:
        yl, yr = np.full(cols.size, ya), np.full(cols.size, yb)
    r0 = np.clip(np.floor(np.minimum(yl, yr)), 0, ny - 1).astype(np.int64)
    r1 = np.clip(np.floor(np.maximum(yl, yr)), 0, ny - 1).astype(np.int64)
    counts = r1 - r0 + 1
    col = np.repeat(cols, counts)
    row = np.repeat(r0, counts) + np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    return col * ny + row
