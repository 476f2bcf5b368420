"""Truth-derived estimator inputs: explicit study options only, never a default (each is warned about and
recorded in the solution config by the dispatch, :mod:`.registry`)."""
from __future__ import annotations

import numpy as np

from ..frames import ecef_to_enu_vec, ecef_to_lla, enu_to_ecef_vec
from ..io import read_gnss, read_truth
from .inputs import AttitudeFixes

TRUTH_KEYS = {"gnss": "the true antenna position/velocity plus white noise as GNSS fixes",
              "align": "the true initial position, velocity and attitude",
              "attitude_source": "the true attitude plus white noise as GNSS attitude fixes"}


def truth_inputs(p, att_source: str | None = None) -> list:
    """The keys of ``p`` (with the resolved ``att_source``) whose value makes the filter read /truth; empty for
    every default. Each is an explicit study option, warned about and recorded in the solution config."""
    used = {"gnss": p.get("gnss"), "align": p.get("align"), "attitude_source": att_source}
    return [k for k in TRUTH_KEYS if used[k] == "truth"]


def truth_fixes(ds, p, a: int):
    """(t (M,) s, pos (M, 3) m ECEF, vel (M, 3) m/s ENU, their covariances): the true position/velocity of antenna
    ``a`` plus white noise of ``truth_pos_sigma_m`` (ENU) and ``truth_vel_sigma_m_per_s`` (a study input, not a
    receiver)."""
    g = read_gnss(ds, antennas=a, truth=("antenna_pos_ecef", "antenna_vel_ecef"), satellites=False)
    t, pos = g.t, g.truth["antenna_pos_ecef"]
    lla = ecef_to_lla(pos)
    vel = ecef_to_enu_vec(g.truth["antenna_vel_ecef"], lla[:, 0], lla[:, 1])
    rng = np.random.default_rng(int(p["seed"]))
    sp = np.broadcast_to(np.asarray(p["truth_pos_sigma_m"], float), 3)
    sv = float(p["truth_vel_sigma_m_per_s"])
    pos = pos + enu_to_ecef_vec(rng.normal(size=pos.shape) * sp, lla[:, 0], lla[:, 1])
    vel = vel + rng.normal(size=vel.shape) * sv
    cov_p = np.broadcast_to(np.diag(sp**2), (t.size, 3, 3))
    return t, pos, vel, cov_p, np.broadcast_to(np.eye(3) * sv**2, (t.size, 3, 3))


def truth_attitude(ds, p) -> AttitudeFixes:
    """The true Euler angles (rad) at the GNSS epochs (the first truth sample at or after each) plus white noise
    of ``attitude_sigma_deg``, as attitude fixes."""
    t = read_gnss(ds, satellites=False).t
    euler = read_truth(ds, t=t, fields=("euler",), required=("euler",)).euler
    sig = np.radians(float(p["attitude_sigma_deg"]))
    rng = np.random.default_rng(int(p["seed"]) + 1)
    return AttitudeFixes(t, euler + rng.normal(size=(t.size, 3)) * sig, np.full(3, sig))


def truth_start(ds):
    """(euler (3,) rad, lla (3,) rad rad m, vel (3,) m/s ENU): the truth at its first sample."""
    tr = read_truth(ds, fields=("euler", "pos_lla", "vel_enu"), required=("euler", "pos_lla", "vel_enu"))
    return tr.euler[0], tr.pos_lla[0], tr.vel_enu[0]
