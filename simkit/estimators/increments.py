"""Coning and sculling: IMU samples -> per-interval rotation vectors and velocity increments (vectorised).

Interval k is (t[k-1], t[k]], body axes. Over each interval the body rate w(t) and specific force f(t) are taken as
polynomials in the normalised time s = (t - t[k-1]) / T, T = t[k] - t[k-1]: w T = a + b s + c s^2,
f T = p + q s + r s^2 (so a, b, c in rad and p, q, r in m/s). The compensation then follows in closed form
(Savage 2000, eqs 7.1.1.1-11 and 7.2.2.2-22 integrated over the interval; 7.2.2.2-20 for the rotation term):
    alpha = a + b/2 + c/3,   dv = p + q/2 + r/3                                   (the increments)
    coning   beta = (a x b + a x c) / 12 + b x c / 60
    sculling (a x q - b x p + a x r - c x p) / 12 + (b x r - c x q) / 60
    rotation (1 - cos|alpha|)/|alpha|^2 alpha x dv + (1 - sin|alpha|/|alpha|)/|alpha|^2 alpha x (alpha x dv)
    phi = alpha + beta,   dvb = dv + rotation + sculling.
The polynomials come from the input, one model for both (exact for quadratic signals, causal):

* **rates** (gyro rad/s, accel m/s^2 sampled at t[k]): the quadratic through the samples t[k-2], t[k-1], t[k]
  (linear in the first interval, where c = r = 0 gives the classic beta = T^2/12 w0 x w1 and sculling
  T^2/12 (w0 x f1 + f0 x w1));
* **increments** (dtheta rad, dvel m/s over each interval, as an integrating IMU outputs them): the quadratic whose
  integrals over the interval and the two before it are the three increments. The first interval is constant,
  the second linear (the classic two-sample corrections dtheta[k-1] x dtheta[k] / 12 and
  (dtheta[k-1] x dv[k] + dv[k-1] x dtheta[k]) / 12). The increments are interval means, not samples at t[k]:
  dtheta / T taken as the rate at t[k] lags by half an interval (1.1 deg of roll at 220 deg/s and 100 Hz).

Both return :class:`Compensated`: ``phi`` (N-1, 3) rad, ``dvb`` (N-1, 3) m/s, ``dt`` (N-1,) s and ``w_ib`` (N, 3)
rad/s, the body rate at each sample time t[k] from the same polynomials (the lever-arm velocity needs it).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import EstimatorInputError


@dataclass(frozen=True)
class Compensated:
    """Per-interval inputs of the mechanisation: ``phi`` (N-1, 3) rad rotation vectors, ``dvb`` (N-1, 3) m/s
    rotation- and sculling-compensated velocity increments, both in the body axes at t[k-1]; ``dt`` (N-1,) s;
    ``w_ib`` (N, 3) rad/s body rate w_ib^b at each sample time."""

    phi: np.ndarray
    dvb: np.ndarray
    dt: np.ndarray
    w_ib: np.ndarray


def _check(name, x, n):
    x = np.asarray(x, dtype=float)
    if x.shape != (n, 3):
        raise EstimatorInputError(f"{name}: expected shape ({n}, 3), got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise EstimatorInputError(f"{name}: expected finite values, found NaN or inf at sample "
                                  f"{int(np.argmax(~np.isfinite(x).all(axis=1)))}")
    return x


def _intervals(t):
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2 or np.any(np.diff(t) <= 0):
        raise EstimatorInputError("t: expected at least 2 strictly increasing sample times (s)")
    return t, np.diff(t)


def _rotation_term(alpha, dv):
    """The velocity rotation term (module docstring) of ``alpha`` (M, 3) rad and ``dv`` (M, 3) m/s; series below
    |alpha| = 1e-3 rad. Its second part matters: without it a steady roll makes a velocity error
    T^3/6 |w|^2 |f_perp| per interval (24 um/s at 220 deg/s, 1 g, 100 Hz)."""
    a2 = np.einsum("ij,ij->i", alpha, alpha)[:, None]
    small = a2 < 1e-6
    a = np.sqrt(np.where(small, 1.0, a2))
    c1 = np.where(small, 0.5 - a2 / 24.0, (1.0 - np.cos(a)) / np.where(small, 1.0, a2))
    c2 = np.where(small, 1.0 / 6.0 - a2 / 120.0, (1.0 - np.sin(a) / a) / np.where(small, 1.0, a2))
    ad = np.cross(alpha, dv)
    return c1 * ad + c2 * np.cross(alpha, ad)


def _compensate(gyro_poly, accel_poly, dt, rate0):
    """Closed-form coning / sculling (module docstring) from the (3, N-1, 3) [a, b, c] and [p, q, r] stacks
    (rad and m/s in normalised time); ``rate0`` (3,) rad/s the body rate at the first sample."""
    a, b, c = gyro_poly
    p, q, r = accel_poly
    alpha = a + b / 2.0 + c / 3.0
    dv = p + q / 2.0 + r / 3.0
    phi = alpha + np.cross(a, b + c) / 12.0 + np.cross(b, c) / 60.0
    sculling = (np.cross(a, q + r) - np.cross(b + c, p)) / 12.0 + (np.cross(b, r) - np.cross(c, q)) / 60.0
    dvb = dv + _rotation_term(alpha, dv) + sculling
    w_end = (a + b + c) / dt[:, None]
    return Compensated(phi, dvb, dt, np.vstack([rate0[None, :], w_end]))


def _interpolate_quadratics(dt, x):
    """(3, M, 3) polynomial coefficients [a, b, c] in normalised time of each interval i = (t[i], t[i+1]] of the
    quadratic through the samples x[i-1], x[i], x[i+1] (linear through x[i], x[i+1] for i = 0), times dt[i]:
    the rate model of :func:`from_rates`. ``x`` (M + 1, 3) samples, ``dt`` (M,) s."""
    T = dt[:, None]
    slope = x[1:] - x[:-1]                            # b + c over the interval, in units of the sample values
    curv = np.zeros_like(slope)
    u = (dt[:-1] / dt[1:])[:, None]                   # the previous sample sits at s = -u
    curv[1:] = (x[:-2] - x[1:-1] + u * slope[1:]) / (u * (1.0 + u))
    return np.stack([x[:-1] * T, (slope - curv) * T, curv * T])


def from_rates(t, gyro, accel) -> Compensated:
    """Compensated increments from rate samples: ``gyro`` (N, 3) rad/s and ``accel`` (N, 3) m/s^2 at ``t`` (N,) s
    (see module docstring)."""
    t, dt = _intervals(t)
    gyro, accel = _check("gyro", gyro, t.size), _check("accel", accel, t.size)
    return _compensate(_interpolate_quadratics(dt, gyro), _interpolate_quadratics(dt, accel), dt, gyro[0])


def _fit_quadratics(dt, inc):
    """(3, M, 3) polynomial coefficients [a, b, c] in normalised time of each interval i whose integrals over the
    intervals i-2, i-1, i are inc[i-2], inc[i-1], inc[i] (fewer at the start: constant for i = 0, linear for
    i = 1). ``inc`` (M, 3), ``dt`` (M,) s.

    The integral Theta(t) of the signal is the cubic through its values at the four interval ends; in Newton form
    about t[i+1], t[i], t[i-1] its divided differences come from the increments alone (no running sum, so no
    cancellation on long records): m = inc / dt, d2 = diff(m) / (t[i+1] - t[i-1]), d3 = diff(d2) / (t[i+1] - t[i-2]).
    With t = t[i] + s T and u = dt[i-1] / T, Theta'(t) T = a + b s + c s^2:
        a = T (m - d2 T - d3 T^2 u),  b = T (2 d2 T + d3 T^2 (2u - 2)),  c = 3 d3 T^3."""
    T = dt[:, None]
    m = inc / T
    d2, d3 = np.zeros_like(m), np.zeros_like(m)
    d2[1:] = (m[1:] - m[:-1]) / (dt[1:] + dt[:-1])[:, None]
    d3[2:] = (d2[2:] - d2[1:-1]) / (dt[2:] + dt[1:-1] + dt[:-2])[:, None]
    u = np.ones_like(T)
    u[1:] = (dt[:-1] / dt[1:])[:, None]
    return np.stack([T * (m - d2 * T - d3 * T**2 * u), T * (2.0 * d2 * T + d3 * T**2 * (2.0 * u - 2.0)),
                     3.0 * d3 * T**3])


def from_increments(t, dtheta, dvel) -> Compensated:
    """Compensated increments from increment samples; ``dtheta[k]`` (rad) / ``dvel[k]`` (m/s) cover
    (t[k-1], t[k]] (the first row is unused). See the module docstring."""
    t, dt = _intervals(t)
    dth, dv = _check("dtheta", dtheta, t.size)[1:], _check("dvel", dvel, t.size)[1:]
    gyro_poly = _fit_quadratics(dt, dth)
    return _compensate(gyro_poly, _fit_quadratics(dt, dv), dt, gyro_poly[0, 0] / dt[0])


def window_mean_rate(comp: Compensated, m: int) -> np.ndarray:
    """Body rate (N, 3) rad/s at each sample s averaged over the ``m`` intervals that end at sample s - 3 (a
    trailing window, truncated at the start): the rotation vectors ``comp.phi`` summed over the window over its
    length (the coning part of phi is second order). It shares no sample with ``comp.w_ib[s]`` (whose quadratic
    model reads samples s-2 .. s, or the increments ending there), so its white noise is independent of that of
    w_ib[s] and m times smaller in variance; it lags the sample by 3 T + m T / 2. ``m`` = 0 gives ``w_ib``."""
    if m <= 0:
        return comp.w_ib.copy()
    n = comp.w_ib.shape[0]
    theta = np.vstack([np.zeros((1, 3)), np.cumsum(comp.phi, axis=0)])   # (N, 3) rad: integral to each sample
    t = np.concatenate([[0.0], np.cumsum(comp.dt)])
    j1 = np.maximum(np.arange(n) - 3, 1)
    j0 = np.maximum(j1 - m, 0)
    return (theta[j1] - theta[j0]) / (t[j1] - t[j0])[:, None]
