"""Stochastic processes shared by the stages: the first-order Gauss-Markov process (exact AR(1) discretisation).

A Gauss-Markov process of stationary standard deviation sigma and correlation time tau, sampled every dt, is
exactly the AR(1) recursion

    x_k = phi x_{k-1} + sigma sqrt(1 - phi^2) w_k,    phi = exp(-dt / tau),  w_k ~ N(0, 1),

for any dt (no small-step approximation); sqrt(1 - phi^2) is computed as sqrt(-expm1(-2 dt / tau)), which
keeps full precision when dt << tau. A process (re)started from its stationary distribution takes x_k = sigma w_k.

A :class:`GaussMarkov` bank serves the GNSS multipath (one process per antenna, satellite, signal and observable,
restarted at each acquisition; a correlation time per signal); the IMU's Gauss-Markov bias takes the coefficients
of :func:`ar1_coefficients`. The recursion runs sample by sample in compiled code, so cutting a record into blocks
in any way gives bit-identical values.
"""
from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["GaussMarkov", "ar1_coefficients"]


def ar1_coefficients(sigma: float, tau_s: float, dt_s: float) -> tuple[float, float]:
    """(phi, drive) of the exact AR(1) recursion x_k = phi x_{k-1} + drive w_k for unit normals w_k."""
    if not (tau_s > 0 and dt_s > 0 and sigma >= 0):
        raise ValueError(f"need sigma >= 0, tau_s > 0 and dt_s > 0, got {sigma!r}, {tau_s!r}, {dt_s!r}")
    return math.exp(-dt_s / tau_s), sigma * math.sqrt(-math.expm1(-2.0 * dt_s / tau_s))


@numba.njit(cache=True, nogil=True)
def _ar1_kernel(w, restart, phi, drive, sigma, state, out):  # pragma: no cover - compiled
    """out[k, i] = sigma w[k, i] where restart[k, i], else phi[i] out[k-1, i] + drive[i] w[k, i]; state[i] carries
    out[-1, i] between calls. ``restart`` of shape (0, 0) means "never restart"."""
    m, n = w.shape
    restarts = restart.shape[0] > 0
    for k in range(m):
        for i in range(n):
            if restarts and restart[k, i]:
                x = sigma * w[k, i]
            else:
                x = phi[i] * state[i] + drive[i] * w[k, i]
            state[i] = x
            out[k, i] = x


_NO_RESTART = np.zeros((0, 0), dtype=np.bool_)


class GaussMarkov:
    """A bank of independent first-order Gauss-Markov processes of one sigma, sampled every dt_s, with correlation
    times ``tau_s``: one number, or an array broadcastable to the bank's ``shape`` (a time per process).

    ``shape`` is the shape of the bank (e.g. ``(3,)`` for three axes). With ``rng`` the processes start from their
    stationary distribution drawn from it and :meth:`block` draws the driving noise from it too; without ``rng``
    the state starts at zero and the caller supplies the noise and the restarts to :meth:`advance`.
    """

    def __init__(self, sigma: float, tau_s, dt_s: float, shape: tuple, rng: np.random.Generator | None = None):
        self.sigma = float(sigma)
        values, inverse = np.unique(np.broadcast_to(np.asarray(tau_s, dtype=float), shape), return_inverse=True)
        coef = np.array([ar1_coefficients(self.sigma, t, dt_s) for t in values]).reshape(-1, 2)
        self.phi, self.drive = (coef[:, k][inverse].reshape(shape) for k in (0, 1))   # (shape) each
        self.rng = rng
        self.state = self.sigma * rng.standard_normal(shape) if rng is not None else np.zeros(shape)

    def advance(self, w: np.ndarray, restart: np.ndarray | None = None, index=()) -> np.ndarray:
        """Advance the processes ``state[index]`` over ``len(w)`` samples; returns their values (M, ...).

        ``w``: unit normals of shape (M,) + state[index].shape. ``restart``: booleans of shape (M,) + a leading
        part of that shape; True restarts every process under it from its stationary distribution (x = sigma w)
        at that sample. ``index`` selects part of the bank (a numpy index); the others keep their state.
        """
        sel = self.state[index]
        m = w.shape[0]
        if w.shape[1:] != sel.shape:
            raise ValueError(f"w must have shape (M,) + {sel.shape}, got {w.shape}")
        flat_w = np.ascontiguousarray(w, dtype=float).reshape(m, -1)
        flags = _NO_RESTART
        if restart is not None:
            r = np.asarray(restart, dtype=np.bool_)
            r = r.reshape(r.shape + (1,) * (w.ndim - r.ndim))
            flags = np.ascontiguousarray(np.broadcast_to(r, w.shape)).reshape(m, -1)
        x = sel.reshape(-1).copy()
        phi, drive = (np.ascontiguousarray(a[index]).reshape(-1) for a in (self.phi, self.drive))
        out = np.empty_like(flat_w)
        _ar1_kernel(flat_w, flags, phi, drive, self.sigma, x, out)
        self.state[index] = x.reshape(sel.shape)
        return out.reshape(w.shape)

    def block(self, count: int) -> np.ndarray:
        """The next ``count`` samples (count,) + shape, driven by the bank's own random stream."""
        if self.rng is None:
            raise ValueError("this bank has no random stream: pass the noise to advance()")
        return self.advance(self.rng.standard_normal((count,) + self.state.shape))
