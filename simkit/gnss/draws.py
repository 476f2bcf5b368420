"""Standard normal draws keyed by (antenna, satellite, epoch), independent of visibility and of the block split.

Each (antenna, satellite) pair owns a PCG64 stream (``simkit.rng``, names ``gnss/ant<a>/<sat id>``). Epoch k of
the run owns the stream's 64-bit outputs [k n, (k + 1) n), n = 5 x (signals of the satellite's system): one
uniform double each, turned into a normal by the inverse CDF (Wichura's algorithm AS 241, PPND16, compiled: within
1.3e-15 relative of scipy's ``ndtri``, at about half its cost). The stream jumps over epochs it does not need
(``advance``), so a satellite's noise at an epoch is the same whether or not the elevation mask, the other
satellites or an outage made it visible at other epochs.
"""
from __future__ import annotations

import math

import numba
import numpy as np

from .. import rng
from .columns import consecutive

DRAWS_PER_SIGNAL = 5  # code, carrier, Doppler, multipath code, multipath carrier
_HALF_ULP = 2.0**-54   # maps PCG64's k / 2^53 doubles into the open interval (0, 1)

# Wichura (1988), Applied Statistics 37, 477-484, algorithm AS 241 (PPND16): numerator and denominator
# coefficients, lowest degree first, of the central region (|p - 1/2| <= 0.425) and of the two tail regions in
# r = sqrt(-log min(p, 1 - p)) (r <= 5 and beyond).
_CENTRAL = np.array([
    [3.3871328727963666080e0, 1.3314166789178437745e+2, 1.9715909503065514427e+3, 1.3731693765509461125e+4,
     4.5921953931549871457e+4, 6.7265770927008700853e+4, 3.3430575583588128105e+4, 2.5090809287301226727e+3],
    [1.0, 4.2313330701600911252e+1, 6.8718700749205790830e+2, 5.3941960214247511077e+3,
     2.1213794301586595867e+4, 3.9307895800092710610e+4, 2.8729085735721942674e+4, 5.2264952788528545610e+3]])
_NEAR_TAIL = np.array([
    [1.42343711074968357734e0, 4.63033784615654529590e0, 5.76949722146069140550e0, 3.64784832476320460504e0,
     1.27045825245236838258e0, 2.41780725177450611770e-1, 2.27238449892691845833e-2, 7.74545014278341407640e-4],
    [1.0, 2.05319162663775882187e0, 1.67638483018380384940e0, 6.89767334985100004550e-1,
     1.48103976427480074590e-1, 1.51986665636164571966e-2, 5.47593808499534494600e-4, 1.05075007164441684324e-9]])
_FAR_TAIL = np.array([
    [6.65790464350110377720e0, 5.46378491116411436990e0, 1.78482653991729133580e0, 2.96560571828504891230e-1,
     2.65321895265761230930e-2, 1.24266094738807843860e-3, 2.71155556874348757815e-5, 2.01033439929228813265e-7],
    [1.0, 5.99832206555887937690e-1, 1.36929880922735805310e-1, 1.48753612908506148525e-2,
     7.86869131145613259100e-4, 1.84631831751005468180e-5, 1.42151175831644588870e-7, 2.04426310338993978564e-15]])


@numba.njit(cache=True, inline="always", error_model="numpy")
def _ratio(c, r):
    """Ratio of the degree-7 polynomials with coefficient rows ``c`` (2, 8) at ``r`` (Horner)."""
    num, den = c[0, 7], c[1, 7]
    for i in range(6, -1, -1):
        num, den = num * r + c[0, i], den * r + c[1, i]
    return num / den


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _quantiles(u, shift, out):
    """Normal quantiles of ``u`` (N,) + ``shift`` into ``out`` (any layout, N elements in C order)."""
    n_g, n_k = out.shape[1], out.shape[2]
    # the central formula everywhere first (branch-free), then the tails
    i = 0
    for m in range(out.shape[0]):
        for g in range(n_g):
            for k in range(n_k):
                q = (u[i] + shift) - 0.5
                out[m, g, k] = q * _ratio(_CENTRAL, 0.180625 - q * q)
                i += 1
    i = 0
    for m in range(out.shape[0]):
        for g in range(n_g):
            for k in range(n_k):
                p = u[i] + shift
                i += 1
                q = p - 0.5
                if abs(q) > 0.425:
                    r = math.sqrt(-math.log(p if q < 0.0 else 1.0 - p))
                    x = _ratio(_NEAR_TAIL, r - 1.6) if r <= 5.0 else _ratio(_FAR_TAIL, r - 5.0)
                    out[m, g, k] = -x if q < 0.0 else x


def normal_quantiles(u) -> np.ndarray:
    """Standard normal quantiles of probabilities ``u`` in (0, 1) (any shape; AS 241: relative error ~1e-16)."""
    u = np.ascontiguousarray(u, dtype=float)
    out = np.empty_like(u)
    _quantiles(u.reshape(-1), 0.0, out.reshape(-1, 1, 1))
    return out


class KeyedNormals:
    """Draws (M, A, C, G, P) for the epochs ``k0 .. k0 + M - 1`` of chosen satellite columns: P = ``per_signal``
    (default :data:`DRAWS_PER_SIGNAL`, the observables' noise) from the streams ``<stream>/ant<a>/<sat id>``
    (default ``gnss``; another error term names its own, so it leaves these untouched)."""

    def __init__(self, seed: int, n_antennas: int, sat_ids, signals_of_sat: list[np.ndarray], n_signals: int,
                 per_signal: int = DRAWS_PER_SIGNAL, stream: tuple[str, ...] = ("gnss",)):
        self.streams = [[rng.generator(seed, *stream, f"ant{a}", sid) for sid in sat_ids] for a in range(n_antennas)]
        self.position = np.zeros((n_antennas, len(sat_ids)), dtype=np.int64)
        self.signals_of_sat = signals_of_sat
        self.n_signals = n_signals
        self.per_signal = per_signal

    def draw(self, k0: int, m: int, cols: np.ndarray) -> np.ndarray:
        """Normals for epochs k0..k0+m-1, satellite columns ``cols`` (C,): (m, A, C, G, P), zero for signals a
        satellite does not transmit."""
        n_ant, per = len(self.streams), self.per_signal
        out = np.zeros((m, n_ant, cols.size, self.n_signals, per))
        buf = np.empty(m * self.n_signals * per)
        for c, s in enumerate(cols):
            sigs = self.signals_of_sat[s]
            per_epoch = sigs.size * per
            view = consecutive(sigs)   # consecutive signals: written through a view
            for a in range(n_ant):
                gen = self.streams[a][s]
                skip = k0 * per_epoch - self.position[a, s]
                if skip < 0:
                    raise ValueError(f"epochs must be drawn in order (epoch {k0} after {self.position[a, s]})")
                gen.bit_generator.advance(int(skip))
                u = gen.random(out=buf[:m * per_epoch])
                if isinstance(view, slice):
                    _quantiles(u, _HALF_ULP, out[:, a, c, view])
                else:
                    out[:, a, c, sigs] = normal_quantiles(u + _HALF_ULP).reshape(m, sigs.size, per)
                self.position[a, s] = (k0 + m) * per_epoch
        return out
