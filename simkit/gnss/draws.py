"""Standard normal draws keyed by (antenna, satellite, epoch), independent of visibility and of the block split.

Each (antenna, satellite) pair owns a PCG64 stream (``simkit.rng``, names ``gnss/ant<a>/<sat id>``). Epoch k of
the run owns the stream's 64-bit outputs [k n, (k + 1) n), n = 5 x (signals of the satellite's system): one
uniform double each, turned into a normal by the inverse CDF. The stream jumps over epochs it does not need
(``advance``), so a satellite's noise at an epoch is the same whether or not the elevation mask, the other
satellites or an outage made it visible at other epochs.
"""
from __future__ import annotations

import numpy as np
from scipy.special import ndtri

from .. import rng

DRAWS_PER_SIGNAL = 5  # code, carrier, Doppler, multipath code, multipath carrier
_HALF_ULP = 2.0**-54   # maps PCG64's k / 2^53 doubles into the open interval (0, 1)


class KeyedNormals:
    """Draws (M, A, C, G, 5) for the epochs ``k0 .. k0 + M - 1`` of chosen satellite columns."""

    def __init__(self, seed: int, n_antennas: int, sat_ids, signals_of_sat: list[np.ndarray], n_signals: int):
        self.streams = [[rng.generator(seed, "gnss", f"ant{a}", sid) for sid in sat_ids] for a in range(n_antennas)]
        self.position = np.zeros((n_antennas, len(sat_ids)), dtype=np.int64)
        self.signals_of_sat = signals_of_sat
        self.n_signals = n_signals

    def draw(self, k0: int, m: int, cols: np.ndarray) -> np.ndarray:
        """Normals for epochs k0..k0+m-1, satellite columns ``cols`` (C,): (m, A, C, G, 5), zero for signals a
        satellite does not transmit."""
        n_ant = len(self.streams)
        out = np.zeros((m, n_ant, cols.size, self.n_signals, DRAWS_PER_SIGNAL))
        for c, s in enumerate(cols):
            sigs = self.signals_of_sat[s]
            per_epoch = sigs.size * DRAWS_PER_SIGNAL
            for a in range(n_ant):
                gen = self.streams[a][s]
                skip = k0 * per_epoch - self.position[a, s]
                if skip < 0:
                    raise ValueError(f"epochs must be drawn in order (epoch {k0} after {self.position[a, s]})")
                gen.bit_generator.advance(int(skip))
                u = gen.random(m * per_epoch) + _HALF_ULP
                out[:, a, c, sigs] = ndtri(u).reshape(m, sigs.size, DRAWS_PER_SIGNAL)
                self.position[a, s] = (k0 + m) * per_epoch
        return out
