"""Free-inertial strapdown navigation in local-level ENU: :func:`strapdown` (arrays in, arrays out)."""
from __future__ import annotations

import numpy as np
from numba import njit
from scipy.spatial.transform import Rotation

from ..frames import euler_from_attitude, lla_to_ecef
from ..solution import Solution
from . import nav
from .errors import EstimatorInputError
from .increments import from_increments, from_rates


@njit(cache=True)
def _integrate(c0, v0, pos0, phi, dvb, dt):
    n = dt.size
    cs = np.empty((n + 1, 3, 3))
    vs = np.empty((n + 1, 3))
    ps = np.empty((n + 1, 3))
    cs[0], vs[0], ps[0] = c0, v0, pos0
    c, v, p, v_prev = c0.copy(), v0.copy(), pos0.copy(), v0.copy()
    for k in range(n):
        c_new, v_new, p, _ = nav.step(c, v, p, v_prev, phi[k], dvb[k], dt[k])
        if k % 64 == 0:
            c_new = nav.orthonormalise(c_new)
        v_prev, v, c = v, v_new, c_new
        cs[k + 1], vs[k + 1], ps[k + 1] = c, v, p
    return cs, vs, ps


def strapdown(t, gyro=None, accel=None, *, pos0_lla, vel0_enu, quat0_nb, dtheta=None, dvel=None) -> Solution:
    """Integrate IMU data from an initial state, without aiding.

    ``t`` (N,) s; either rates ``gyro`` (N, 3) rad/s and ``accel`` (N, 3) m/s^2 (body, w_ib^b and f_ib^b), or
    increments ``dtheta`` (N, 3) rad and ``dvel`` (N, 3) m/s (row k covers (t[k-1], t[k]]). Initial state at
    t[0]: ``pos0_lla`` [lat rad, lon rad, h m], ``vel0_enu`` (3,) m/s, ``quat0_nb`` (4,) body->ENU scalar-last.
    Returns a :class:`Solution` at every sample (no covariance).

    >>> import numpy as np; from simkit.earth import earth_rate_enu, normal_gravity
    >>> t = np.arange(101) * 0.01; w = np.tile(earth_rate_enu(0.6), (101, 1))
    >>> f = np.tile([0.0, 0.0, normal_gravity(0.6, 0.0)], (101, 1))
    >>> sol = strapdown(t, w, f, pos0_lla=[0.6, 0.1, 0.0], vel0_enu=[0, 0, 0], quat0_nb=[0, 0, 0, 1])
    >>> bool(np.abs(sol.vel_enu).max() < 1e-9)
    True
    """
    if (gyro is None) == (dtheta is None):
        raise EstimatorInputError("strapdown: give either gyro/accel (rates) or dtheta/dvel (increments)")
    comp = from_rates(t, gyro, accel) if gyro is not None else from_increments(t, dtheta, dvel)
    pos0 = _vec("pos0_lla", pos0_lla, 3)
    v0 = _vec("vel0_enu", vel0_enu, 3)
    q0 = _vec("quat0_nb", quat0_nb, 4)
    c0 = Rotation.from_quat(q0).as_matrix()
    cs, vs, ps = _integrate(c0, v0, pos0, comp.phi, comp.dvb, comp.dt)
    rot = Rotation.from_matrix(cs)
    return Solution(t=np.asarray(t, float), pos_ecef=lla_to_ecef(ps[:, 0], ps[:, 1], ps[:, 2]), vel_enu=vs,
                    quat_nb=rot.as_quat(), euler=euler_from_attitude(rot),
                    config={"estimator": "strapdown", "input": "rates" if gyro is not None else "increments"})


def _vec(name, x, n):
    x = np.asarray(x, dtype=float)
    if x.shape != (n,) or not np.all(np.isfinite(x)):
        raise EstimatorInputError(f"{name}: expected {n} finite numbers, got {x!r}")
    return x
