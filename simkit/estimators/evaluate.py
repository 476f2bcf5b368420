"""Errors of a solution against the file's truth, per epoch and as RMS per axis (for the studies and peers)."""
from __future__ import annotations

import numpy as np

from ..frames import ecef_to_enu_vec


def errors_vs_truth(ds, sol):
    """Per-epoch errors of a solution: position ENU (m), velocity ENU (m/s), attitude [pitch, roll, heading]
    differences (rad, wrapped), at the truth samples nearest the solution epochs."""
    k = np.clip(np.searchsorted(ds["truth/t"][:], sol.t - 1e-9), 0, ds["truth/t"].shape[0] - 1)
    lla = ds["truth/pos_lla"][:][k]
    dp = ecef_to_enu_vec(sol.pos_ecef - ds["truth/pos_ecef"][:][k], lla[:, 0], lla[:, 1])
    dv = sol.vel_enu - ds["truth/vel_enu"][:][k]
    de = None
    if sol.euler is not None:
        de = (sol.euler - ds["truth/euler"][:][k] + np.pi) % (2 * np.pi) - np.pi
    return dp, dv, de


def rms_table(ds, sol, skip_s):
    """RMS after ``skip_s`` s of [pos E, N, U (m), vel E, N, U (m/s), pitch, roll, heading (deg)]."""
    dp, dv, de = errors_vs_truth(ds, sol)
    m = sol.t >= skip_s
    r = lambda x: np.sqrt(np.mean(x[m] ** 2, axis=0))  # noqa: E731
    return np.concatenate([r(dp), r(dv), np.degrees(r(de))])


