"""Receiver position from code (single-point, vectorised over epochs) and lines of sight in ENU.

Only the line-of-sight directions and elevations need the receiver position here: a position error of 10 m
turns a line of sight by ~5e-7 rad (5 um over a 10 m baseline), so a code solution without atmospheric models
is ample. Satellite positions are those of the file (ECEF of the transmit epoch); the Earth rotation during the
signal's travel (Sagnac) is applied here by rotating them into the ECEF frame of the receive epoch.
"""
from __future__ import annotations

import numpy as np

from ..constellation.geometry import lines_of_sight_enu, sagnac_rotate
from ..gnss.differencing import systems_of
from ..gnss.spp import spp


def code_position(code: np.ndarray, sat_pos: np.ndarray, sat_clock: np.ndarray, sat_ids) -> np.ndarray:
    """Single-point position (M, 3) m ECEF from code (M, S) m, satellites (M, S, 3) m, clocks (M, S) s and the
    satellite ids (S,): :func:`simkit.gnss.spp.spp` with its troposphere, one clock per system and no ionosphere
    model (metres of error, ample here). NaN rows where fewer satellites than unknowns have code."""
    ids = np.asarray(sat_ids).astype(str)
    return spp(np.arange(len(code), dtype=float), code, None, np.ones(len(ids)), sat_pos, sat_clock,
               systems_of(ids)).pos_ecef


def lines_of_sight(receiver: np.ndarray, sat_pos: np.ndarray):
    """Unit lines of sight receiver -> satellite in ENU (M, S, 3) and elevations (M, S) rad, Sagnac applied."""
    return lines_of_sight_enu(receiver, sagnac_rotate(sat_pos, receiver))
