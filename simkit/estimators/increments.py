"""Coning and sculling: IMU samples -> per-interval rotation vectors and velocity increments (vectorised).

Interval k is (t[k-1], t[k]], body axes. Two inputs:

* **rates** (gyro rad/s, accel m/s^2 sampled at t[k]): the signals are taken linear over the interval, so
  dtheta = (w0 + w1) T / 2, dv = (f0 + f1) T / 2, and the second-order terms are exact for linear signals:
  coning  beta = T^2/12 w0 x w1,   sculling  T^2/12 (w0 x f1 + f0 x w1)   (Savage 2000, eqs 7.1.1.1-11, 7.2.2.2-22,
  integrated in closed form for linear w(t), f(t));
* **increments** (dtheta rad, dvel m/s over each interval, as an integrating IMU outputs them): the classic
  two-sample corrections, beta = dtheta[k-1] x dtheta[k] / 12, sculling (dtheta[k-1] x dv[k] + dv[k-1] x
  dtheta[k]) / 12.

Both add the rotation term dtheta x dv / 2. Returns (phi (N-1, 3) rad, dvb (N-1, 3) m/s, dt (N-1,) s).
"""
from __future__ import annotations

import numpy as np

from .errors import EstimatorInputError


def _check(name, x, n):
    x = np.asarray(x, dtype=float)
    if x.shape != (n, 3):
        raise EstimatorInputError(f"{name}: expected shape ({n}, 3), got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise EstimatorInputError(f"{name}: expected finite values, found NaN or inf at sample "
                                  f"{int(np.argmax(~np.isfinite(x).all(axis=1)))}")
    return x


def from_rates(t, gyro, accel):
    """Rotation vectors and velocity increments from rate samples (see module docstring)."""
    t = np.asarray(t, dtype=float)
    gyro, accel = _check("gyro", gyro, t.size), _check("accel", accel, t.size)
    dt = np.diff(t)
    if t.ndim != 1 or t.size < 2 or np.any(dt <= 0):
        raise EstimatorInputError("t: expected at least 2 strictly increasing sample times (s)")
    w0, w1, f0, f1 = gyro[:-1], gyro[1:], accel[:-1], accel[1:]
    T = dt[:, None]
    dth = 0.5 * (w0 + w1) * T
    dv = 0.5 * (f0 + f1) * T
    phi = dth + T**2 / 12.0 * np.cross(w0, w1)
    dvb = dv + 0.5 * np.cross(dth, dv) + T**2 / 12.0 * (np.cross(w0, f1) + np.cross(f0, w1))
    return phi, dvb, dt


def from_increments(t, dtheta, dvel):
    """Rotation vectors and velocity increments from increment samples; ``dtheta[k]``/``dvel[k]`` cover
    (t[k-1], t[k]] (the first row is unused)."""
    t = np.asarray(t, dtype=float)
    dth, dv = _check("dtheta", dtheta, t.size)[1:], _check("dvel", dvel, t.size)[1:]
    dt = np.diff(t)
    if t.ndim != 1 or t.size < 2 or np.any(dt <= 0):
        raise EstimatorInputError("t: expected at least 2 strictly increasing sample times (s)")
    pth = np.vstack([dth[:1], dth[:-1]])  # the first interval has no predecessor: its own value (no correction)
    pdv = np.vstack([dv[:1], dv[:-1]])
    phi = dth + np.cross(pth, dth) / 12.0
    dvb = dv + 0.5 * np.cross(dth, dv) + (np.cross(pth, dv) + np.cross(pdv, dth)) / 12.0
    return phi, dvb, dt
