"""Acquisition of rising satellites: a receiver starts tracking a satellite some time after it comes into view.

A real receiver searches for a satellite that rises above its mask (or reappears from behind an obstruction) and
needs a few seconds to minutes, and a stronger signal than it needs to keep tracking, before the first observation;
a setting satellite stays tracked down to the mask. ``[gnss.acquisition]``:

    delay_s        a satellite is first tracked delay_s after it became visible (each new visible run: a rising
                   satellite, or one back after an outage or a blockage: reacquisition)
    elevation_deg  and not before it is at least this high (the acquisition C/N0 threshold above the tracking
                   one, expressed as the elevation where the C/N0 model reaches it for a static antenna)

Satellites visible at the first epoch of the run are tracked from it (the receiver was running before the file
starts). Both keys default to no delay and no elevation, so a scenario without the table is unchanged
(``simkit twin --fit`` estimates ``delay_s`` from a real file, docs/real_data.md). Deterministic: no random draw,
so no stream of any other component moves. The state (the start of each satellite's visible run, whether it is
acquired) is carried between blocks, so the block split does not matter.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..section import Section, in_range, non_negative


@dataclass(frozen=True)
class AcquisitionConfig:
    delay_s: float = 0.0                  # from the start of a visible run to the first tracked epoch
    elevation_rad: float | None = None    # lowest elevation at which a satellite is acquired; None: the mask

    @property
    def active(self) -> bool:
        return self.delay_s > 0.0 or self.elevation_rad is not None


def parse_acquisition(sec: Section) -> AcquisitionConfig:
    """Read ``[gnss.acquisition]`` (``sec`` at path "gnss.acquisition")."""
    delay = sec.get("delay_s", float, 0.0, check=non_negative)
    el = sec.get("elevation_deg", float, None, check=in_range(-90.0, 90.0))
    sec.done()
    return AcquisitionConfig(delay_s=delay, elevation_rad=None if el is None else float(np.radians(el)))


class Acquisition:
    """The acquisition state of (antenna, satellite) pairs (A, S)."""

    def __init__(self, cfg: AcquisitionConfig, n_antennas: int, n_sats: int):
        self.cfg = cfg
        shape = (n_antennas, n_sats)
        self.prev = np.ones(shape, dtype=bool)       # "visible before the run": satellites up at t = 0 are tracked
        self.acquired = np.ones(shape, dtype=bool)
        self.run_start = np.full(shape, -np.inf)

    def apply(self, t, visible, elevation, cols=slice(None)) -> np.ndarray:
        """Tracked (M, A, C) bool: ``visible`` (M, A, C) (above the mask, not blocked) and acquired, at epochs
        ``t`` (M,) s with ``elevation`` (M, A, C) rad, for the satellite columns ``cols`` of the state."""
        if not self.cfg.active:
            return visible
        t = np.asarray(t, float)
        m = t.size
        prev = np.concatenate([self.prev[None, :, cols], visible[:-1]], axis=0)
        start = visible & ~prev
        k = np.arange(m)[:, None, None]
        last = np.maximum.accumulate(np.where(start, k, -1), axis=0)
        run_start = np.where(last >= 0, t[np.maximum(last, 0)], self.run_start[None, :, cols])
        cond = visible & (t[:, None, None] - run_start >= self.cfg.delay_s - 1e-9)
        if self.cfg.elevation_rad is not None:
            with np.errstate(invalid="ignore"):
                cond &= elevation >= self.cfg.elevation_rad
        cs = np.cumsum(cond, axis=0)
        base = np.maximum.accumulate(np.where(start, cs - cond, -1), axis=0)
        continuing = last < 0                          # the run began before this block
        acquired = np.where(continuing, self.acquired[None, :, cols] | (cs > 0), cs - base > 0) & visible
        self.prev[:, cols] = visible[-1]
        self.run_start[:, cols] = run_start[-1]
        self.acquired[:, cols] = acquired[-1]
        return acquired
