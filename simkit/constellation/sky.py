"""A sky: several constellations (e.g. GPS from one file, BDS from another) seen as one satellite list.

Built by the constellation stage from a list of sources and handed to the GNSS stage, which never loads files.
"""
from __future__ import annotations

import numpy as np

from .geometry import receiver_view
from .model import Constellation
from .sources import load

_VIEW_FIELDS = ("sat_pos", "sat_pos_emission", "sat_vel", "sat_clock", "sat_drift", "tau", "elevation")


class Sky:
    """The satellites of ``constellations`` in order; ``sat_ids`` (S,) and per-system broadcast parameters."""

    def __init__(self, constellations: list[Constellation]):
        self.constellations = list(constellations)
        self.sat_ids = [s for c in self.constellations for s in c.sat_ids]
        seen: set[str] = set()
        self.duplicates = sorted({s for s in self.sat_ids if s in seen or seen.add(s)})

    @property
    def channels(self) -> np.ndarray:
        """(S,) int GLONASS FDMA frequency numbers (0 for CDMA satellites)."""
        return np.concatenate([c.channels for c in self.constellations]) if self.constellations else \
            np.zeros(0, np.int64)

    @property
    def sources(self) -> list[str]:
        return [c.source for c in self.constellations]

    def view(self, rx_pos, gps_week, gps_sow, reception_grid: bool = False) -> dict[str, np.ndarray]:
        """Light-time geometry for receivers at ``rx_pos`` (M, 3) m ECEF at reception (``gps_week``, ``gps_sow``
        (M,) s): ``sat_pos`` (M, S, 3) m at emission in the ECEF frame of reception, ``sat_pos_emission`` the same
        in the ECEF frame of emission, ``sat_vel`` (M, S, 3) m/s, ``sat_clock`` (M, S) s, ``sat_drift`` (M, S)
        s/s, ``tau`` (M, S) s light time, ``elevation`` (M, S) rad (see :func:`receiver_view`, also for
        ``reception_grid``)."""
        parts = [receiver_view(c, rx_pos, gps_week, gps_sow, velocity=True, reception_grid=reception_grid)
                 for c in self.constellations]
        return {k: np.concatenate([getattr(p, k) for p in parts], axis=1) for k in _VIEW_FIELDS}

    def klobuchar(self, system: str):
        """The broadcast Klobuchar (alpha, beta) of ``system`` ('G' or 'C') from the first source with one."""
        for c in self.constellations:
            k = c.klobuchar.get(system)
            if k is not None:
                return tuple(k.alpha), tuple(k.beta)
        return None

    def time_offsets(self) -> dict:
        """Broadcast system-time offsets by kind (``Constellation.time_offsets``), the first source's per kind."""
        out: dict = {}
        for c in self.constellations:
            for kind, off in c.time_offsets.items():
                out.setdefault(kind, off)
        return out

    def group_delays(self, gps_week, gps_sow) -> dict[str, np.ndarray]:
        """Broadcast group delays name -> (S,) s (NaN where a source has none), records nearest the epoch."""
        out: dict[str, np.ndarray] = {}
        offset = 0
        for c in self.constellations:
            n = len(c.sat_ids)
            for name, vals in c.group_delays(gps_week, gps_sow).items():
                out.setdefault(name, np.full(len(self.sat_ids), np.nan))[offset:offset + n] = vals
            offset += n
        return out


def load_sky(sources, systems: str | None = None) -> Sky:
    """A :class:`Sky` of the constellations loaded from ``sources`` (see :func:`load`), in order; ``systems``
    (RINEX navigation sources only) the system letters to keep (default all)."""
    return Sky([load(s, systems=systems) for s in sources])
