"""Broadcast system-time offsets to GPS time, from a navigation file's header ('TIME SYSTEM CORR', RINEX 3) or
its '> STO' records (RINEX 4), as :mod:`.rinex_nav` reads them into ``Constellation.time_offsets``.

Each kind gives a0 (s), a1 (s/s) and a reference time; at GPS time t the offset is a0 + a1 (t - t_ref). The kinds
used here are system time minus GPS time: ``GAGP`` the Galileo GGTO (OS SIS ICD 5.1.8: t_GST - t_GPS),
``QZGP`` QZSST - GPST, ``BDGP`` the fractional BDT - GPST beyond the whole 14 s (BDS CNAV BGTO). GLONASS
(``GLGP``, tau_GPS) is left out: its sign convention (GLONASS ICD: T_GPS - T_GL = whole seconds + tau_GPS) is the
opposite, and simkit's GLONASS clocks are already referred to UTC(SU)-based time with ``GLUT`` unapplied, so a
GLONASS offset would need both terms; GLONASS keeps its own receiver clock instead.
"""
from __future__ import annotations

import numpy as np

from .. import gpstime

KIND = {"E": "GAGP", "J": "QZGP", "C": "BDGP"}  # system time minus GPS time


def polynomials(offsets: dict, systems) -> dict[str, tuple[float, float, int, float]]:
    """{system: (a0 s, a1 s/s, t_ref GPS week, t_ref s of week)} for the ``systems`` whose offset ``offsets``
    (``Constellation.time_offsets``) broadcasts; GPS and systems without one are left out."""
    out = {}
    for sys in systems:
        off = offsets.get(KIND.get(sys, ""))
        if off is not None:
            out[sys] = (float(off.a0), float(off.a1), int(off.t_ref[0]), float(off.t_ref[1]))
    return out


def evaluate(poly: dict, systems, gps_week, gps_sow):
    """System time minus GPS time (s) and its rate (s/s), each (..., S), for satellites of ``systems`` (S,) at GPS
    times (``gps_week``, ``gps_sow``) broadcast to a shape T: T + (S,); 0 where ``poly`` has no polynomial for a
    satellite's system (GPS, or none broadcast)."""
    systems = np.asarray(systems)
    week, sow = np.broadcast_arrays(np.asarray(gps_week), np.asarray(gps_sow, dtype=float))
    value = np.zeros(week.shape + systems.shape)
    rate = np.zeros(week.shape + systems.shape)
    for sys, (a0, a1, w0, s0) in poly.items():
        cols = systems == sys
        if cols.any():
            dt = np.asarray(gpstime.diff_seconds(week, sow, w0, s0), dtype=float)[..., None]
            value[..., cols] = a0 + a1 * dt
            rate[..., cols] = a1
    return value, rate
