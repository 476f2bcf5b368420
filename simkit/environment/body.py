"""Masking by the vehicle's own body: per antenna an elevation mask over azimuth, and boxes, in the body frame.

Body frame: x right, y forward, z up. A body azimuth is clockwise from forward (body y) seen from above, a body
elevation is above the body's x-y plane. A mask table blocks directions below the elevation interpolated
(linearly, periodically) at their azimuth; a box (its min and max corners in metres from the IMU centre) blocks
the lines of sight from an antenna that pass through it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class MaskTable:
    """Elevation mask ``elevation_rad`` (K,) at body azimuths ``azimuth_rad`` (K,) increasing in [0, 2 pi), for
    the antennas ``antennas`` (None: every antenna)."""

    azimuth_rad: np.ndarray
    elevation_rad: np.ndarray
    antennas: tuple[int, ...] | None


@dataclass(frozen=True)
class Box:
    """Axis-aligned box in the body frame, corners ``lo`` and ``hi`` (3,) m, for ``antennas`` (None: all)."""

    lo: np.ndarray
    hi: np.ndarray
    antennas: tuple[int, ...] | None


def mask_elevation(table: MaskTable, az_b) -> np.ndarray:
    """The table's mask elevation (rad) at body azimuths ``az_b`` (rad, any shape)."""
    return np.interp(np.mod(az_b, 2 * np.pi), table.azimuth_rad, table.elevation_rad, period=2 * np.pi)


def box_blocks(box: Box, origin_b, los_b) -> np.ndarray:
    """Whether rays from ``origin_b`` (..., 3) m along unit vectors ``los_b`` (..., 3) (body frame) pass through
    ``box`` (slab test, forward intersections only)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / los_b
        t_a = (box.lo - origin_b) * inv
        t_b = (box.hi - origin_b) * inv
    lo_t, hi_t = np.minimum(t_a, t_b), np.maximum(t_a, t_b)
    inside = (origin_b >= box.lo) & (origin_b <= box.hi)
    parallel = los_b == 0.0
    lo_t = np.where(parallel, np.where(inside, -np.inf, np.inf), lo_t)   # a ray parallel to a slab: all or nothing
    hi_t = np.where(parallel, np.where(inside, np.inf, -np.inf), hi_t)
    enter, leave = lo_t.max(axis=-1), hi_t.min(axis=-1)
    return (leave >= np.maximum(enter, 0.0)) & (leave > 0.0)


def body_blocked(tables, boxes, lever_b, los_b) -> np.ndarray:
    """Whether each line of sight ``los_b`` (M, A, C, 3) (unit, body frame) from the antennas at ``lever_b``
    (A, 3) m is masked by the body; (M, A, C) bool."""
    out = np.zeros(los_b.shape[:-1], dtype=bool)
    n_ant = lever_b.shape[0]
    az = np.arctan2(los_b[..., 0], los_b[..., 1])
    el = np.arcsin(np.clip(los_b[..., 2], -1.0, 1.0))
    for tab in tables:
        ants = range(n_ant) if tab.antennas is None else tab.antennas
        for a in ants:
            out[:, a] |= el[:, a] < mask_elevation(tab, az[:, a])
    for box in boxes:
        ants = range(n_ant) if box.antennas is None else box.antennas
        for a in ants:
            out[:, a] |= box_blocks(box, lever_b[a], los_b[:, a])
    return out
