"""Carrier tracking per channel (antenna, satellite, signal): true integer ambiguities, cycle slips, LLI flags.

Events per channel, in time order: acquisition (a new random integer ambiguity), random slips (a Poisson process
of rate ``gnss.slip_rate_per_h``) and scheduled slips (``[[gnss.slip]]``: the given or a random non-zero number of
cycles). Every (antenna, satellite) pair draws its events from its own stream, in time order, and the state
carried between calls (ambiguities, tracking, next Poisson slip) makes the output independent of the block split.
"""
from __future__ import annotations

import heapq

import numpy as np

from .. import rng
from . import signals
from .config import GnssConfig

LLI_LOSS_OF_LOCK = 1  # RINEX LLI bit 0: lost lock since the previous observation, a cycle slip is possible
_ACQUIRE, _POISSON, _SCHEDULED = 0, 1, 2
_RANDOM_SLIP_MAX_CYCLES = 50


class Tracking:
    """Ambiguity and slip state of the channels (A, S, G)."""

    def __init__(self, cfg: GnssConfig, seed: int, sat_ids, n_antennas: int):
        self.cfg = cfg
        shape = (n_antennas, len(sat_ids), len(cfg.signals))
        self.streams = [[rng.generator(seed, "gnss", f"ant{a}", sid, "events") for sid in sat_ids]
                        for a in range(n_antennas)]
        self.tracked = np.zeros(shape, dtype=bool)
        self.amb = np.zeros(shape, dtype=np.int64)
        self.sat_index = {sid: k for k, sid in enumerate(sat_ids)}
        self.sig_index = {n: j for j, n in enumerate(cfg.signals)}
        self.slip_rate = cfg.slip_rate_per_h / 3600.0 if cfg.errors["cycle_slips"] else 0.0
        self.next_slip = np.full(shape, np.inf)
        if self.slip_rate > 0:
            # a GPS/BDS satellite draws a first slip time for every GPS/BDS signal (as before other systems
            # existed: their files stay the same), a Galileo/QZSS/GLONASS satellite for its own signals only, so
            # adding a system's signals leaves the other satellites' event streams alone
            sig_sys = np.array([signals.get(n).system for n in cfg.signals])
            legacy = np.isin(sig_sys, ("G", "C"))
            for s, sid in enumerate(sat_ids):
                cols = np.flatnonzero(legacy if sid[0] in "GC" else sig_sys == sid[0])
                for a in range(n_antennas):
                    self.next_slip[a, s, cols] = self.streams[a][s].exponential(1.0 / self.slip_rate, cols.size)
        self.t_last = -np.inf

    def advance(self, t: np.ndarray, tracked: np.ndarray, reacquire: np.ndarray | None = None):
        """Ambiguities (M, A, S, G) int64 cycles and LLI flags (M, A, S, G) uint8 at epochs ``t`` (M,) s, given
        which channels are tracked (M, A, S, G); ``reacquire`` (M, A, S, G), optional: channels that lose lock
        and reacquire at that epoch although tracked before (the loop switched to another ray)."""
        events = self._acquisitions(tracked, reacquire)
        if self.cfg.errors["cycle_slips"]:
            self._poisson_starts(t, events)
            self._scheduled(t, events)
        amb = np.broadcast_to(self.amb, (t.size,) + self.amb.shape).copy()
        lli = np.zeros((t.size,) + self.amb.shape, dtype=np.uint8)
        for (a, s), evs in events.items():
            self._apply(t, tracked, a, s, evs, amb, lli)
        self.amb = amb[-1].copy()
        self.tracked = tracked[-1].copy()
        self.t_last = float(t[-1])
        return amb, lli

    def _acquisitions(self, tracked, reacquire=None) -> dict:
        prev = np.concatenate([self.tracked[None], tracked[:-1]], axis=0)
        new = tracked & ~prev if reacquire is None else tracked & (~prev | reacquire)
        events: dict[tuple, list] = {}
        for k, a, s, g in zip(*np.nonzero(new)):
            events.setdefault((a, s), []).append((k, g, _ACQUIRE, None))
        return events

    def _poisson_starts(self, t, events) -> None:
        for a, s, g in zip(*np.nonzero(self.next_slip <= t[-1])):
            k = int(np.searchsorted(t, self.next_slip[a, s, g] - 1e-9))
            events.setdefault((a, s), []).append((k, g, _POISSON, None))

    def _scheduled(self, t, events) -> None:
        n_ant, n_sat, n_sig = self.amb.shape
        for sl in self.cfg.slips:
            k = int(np.searchsorted(t, sl.t_s - 1e-9))  # first epoch at or after the slip
            if k >= t.size or sl.t_s <= self.t_last:
                continue
            ants = [sl.antenna] if sl.antenna is not None else range(n_ant)
            sats = [self.sat_index[sl.sat]] if sl.sat is not None else range(n_sat)
            sigs = [self.sig_index[sl.signal]] if sl.signal is not None else range(n_sig)
            for a in ants:
                for s in sats:
                    for g in sigs:
                        events.setdefault((a, s), []).append((k, g, _SCHEDULED, sl.cycles))

    def _apply(self, t, tracked, a, s, evs, amb, lli) -> None:
        """Apply one (antenna, satellite) pair's events in time order (ties: signal, then kind)."""
        gen = self.streams[a][s]
        big = self.cfg.ambiguity_max_cycles
        heap = [(k, g, kind, 0 if cyc is None else cyc, cyc is None) for k, g, kind, cyc in evs]
        heapq.heapify(heap)
        while heap:
            k, g, kind, cyc, random_cycles = heapq.heappop(heap)
            if kind == _ACQUIRE:
                amb[k:, a, s, g] = gen.integers(-big, big + 1)
                lli[k, a, s, g] |= LLI_LOSS_OF_LOCK
                continue
            if kind == _POISSON:  # schedule the next slip of this chain first
                self.next_slip[a, s, g] += gen.exponential(1.0 / self.slip_rate)
                if self.next_slip[a, s, g] <= t[-1]:
                    k_next = int(np.searchsorted(t, self.next_slip[a, s, g] - 1e-9))
                    heapq.heappush(heap, (k_next, g, _POISSON, 0, True))
            if random_cycles:
                cyc = int(gen.integers(1, _RANDOM_SLIP_MAX_CYCLES + 1)) * (1 if gen.random() < 0.5 else -1)
            if tracked[k, a, s, g]:
                amb[k:, a, s, g] += cyc
                lli[k, a, s, g] |= LLI_LOSS_OF_LOCK
