"""Multipath: first-order Gauss-Markov processes per antenna, satellite and signal, scaled with elevation.

Each (antenna, satellite, signal, code/carrier) multipath is a unit-variance first-order Gauss-Markov process
(the exact AR(1) bank of :mod:`simkit.processes`), restarted from its stationary distribution at each
(re)acquisition of its satellite: multipath after an outage is independent of what it was before. The error is
sigma(el) x with sigma(el) = sigma_horizon exp(-el / el0): large near the horizon, small at zenith (the exponential
elevation profile of Kee & Parkinson-type multipath models).
"""
from __future__ import annotations

import numpy as np

from ..processes import GaussMarkov


def elevation_scale(el, sigma_horizon, el0_rad):
    """Multipath standard deviation at elevation ``el`` (rad)."""
    return sigma_horizon * np.exp(-np.asarray(el) / el0_rad)


def multipath_bank(dt_s: float, tau_s, shape: tuple) -> GaussMarkov:
    """The unit-variance bank of shape (A, S, G, 2) [antenna, satellite, signal, code/carrier], correlation times
    ``tau_s`` s (a number, or broadcastable to ``shape``: (G, 1) one per signal).

    Advance the visible satellites ``cols`` with ``bank.advance(w, restart, index=(slice(None), cols))``:
    ``w`` (M, A, C, G, 2) standard normals, ``restart`` (M, A, C) True at each (re)acquisition.
    """
    return GaussMarkov(1.0, tau_s, dt_s, shape)
