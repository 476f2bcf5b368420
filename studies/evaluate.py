"""RMS errors of a solution against the file's truth, per axis, for the studies and the peer comparison.

The errors themselves are the referee's (:func:`simkit.referee.compare`: estimate minus truth at the estimate's
epochs and point, position ENU m, velocity ENU m/s, Euler [pitch, roll, heading] rad wrapped to [-pi, pi)).
"""
from __future__ import annotations

import numpy as np

from simkit.referee import compare, read_truth


def errors_vs_truth(ds, sol):
    """The referee's errors of ``sol`` against the truth of the open simkit file ``ds``: (t (K,) s, position
    ENU (K, 3) m, velocity ENU (K, 3) m/s, Euler differences (K, 3) rad or None)."""
    err = compare(read_truth(ds.path, float(np.nanmin(sol.t)), float(np.nanmax(sol.t))), sol, str(ds.path))
    return err.t, err.pos_enu, err.vel_enu, err.euler


def rms_table(ds, sol, skip_s):
    """RMS after ``skip_s`` s of [pos E, N, U (m), vel E, N, U (m/s), pitch, roll, heading (deg)]."""
    t, dp, dv, de = errors_vs_truth(ds, sol)
    m = t >= skip_s
    r = lambda x: np.sqrt(np.mean(x[m] ** 2, axis=0))  # noqa: E731
    return np.concatenate([r(dp), r(dv), np.degrees(r(de))])
