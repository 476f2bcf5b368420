"""Nominal constellations from published slot definitions (circular orbits; no clocks).

Names for ``load("nominal:<name>")``: ``gps`` (24-slot baseline), ``bds2`` (5 GEO + 5 IGSO + 4 MEO), ``bds3``
(24 MEO Walker 24/3/1 + 3 GEO + 3 IGSO), ``bds`` (= ``bds3``), ``gps+bds`` (gps and bds3 together), ``gal``
(Galileo Walker 24/3/1), ``glo`` (GLONASS 24 slots, with the slots' FDMA channels), ``gps+bds+gal+glo``.

GPS: SPS Performance Standard (2001 Table 3-1, 2008/2020 Table 3.1-1) baseline 24-slot table: RAAN and argument of
latitude per slot at the defined epoch 1 July 1993 00:00 UTC, Greenwich hour angle 18 h 36 min 14.4 s, i = 55 deg,
a = 26,559.7 km, e = 0. Slot A1..F4 are given PRNs G01..G24 in that order (the slot-to-PRN map is not published).
BDS: China Satellite Navigation Office, "Development of the BeiDou Navigation Satellite System" (v4.0, 2019) and
BDS-SIS-ICD: MEO a = 27,906.1 km (21,528 km altitude), i = 55 deg, Walker 24/3/1; GEO at 35,786 km altitude over
140E (C01/C59), 80E (C02/C60), 110.5E (C03/C61), 160E (C04), 58.75E (C05); IGSO i = 55 deg with equator crossings
at 118E (C06-C08, C38-C40, 120 deg apart) and 95E (C09, C10). Where a value is not published (the Walker planes'
node longitudes, the MEO slot-to-PRN map, the C09/C10 phases) we chose it; see docs/constellation.md.

Mean motions are set so that ground tracks repeat exactly (GPS: 2 revolutions per day, BDS MEO: 13 per 7 days,
GEO/IGSO: 1 per day, days relative to the precessing node), which is what station keeping maintains, so the
geometry neither drifts away from the published slots over decades nor depends on the reference epoch.
MEO nodes regress at the J2 rate -1.5 J2 (Re/a)^2 n cos i; GEO/IGSO nodes are held fixed.
"""
from __future__ import annotations

from datetime import datetime, timezone

import numpy as np

from .. import gpstime
from ..earth import A as R_EARTH
from ..errors import DataFileError
from . import kepler
from . import glonass
from .model import KeplerConstellation, Records
from .systems import BDS, GAL, GPS, System

J2 = 1.08262668e-3  # WGS-84 (EGM96) second zonal harmonic
DEG = np.pi / 180.0

# SPS PS baseline 24-slot table: slot -> (RAAN deg, argument of latitude deg) at 1993-07-01 00:00 UTC
GPS_SLOTS = {
    "A1": (272.847, 268.126), "A2": (272.847, 161.786), "A3": (272.847, 11.676), "A4": (272.847, 41.806),
    "B1": (332.847, 80.956), "B2": (332.847, 173.336), "B3": (332.847, 309.976), "B4": (332.847, 204.376),
    "C1": (32.847, 111.876), "C2": (32.847, 11.796), "C3": (32.847, 339.666), "C4": (32.847, 241.556),
    "D1": (92.847, 135.226), "D2": (92.847, 265.446), "D3": (92.847, 35.156), "D4": (92.847, 167.356),
    "E1": (152.847, 197.046), "E2": (152.847, 302.596), "E3": (152.847, 66.066), "E4": (152.847, 333.686),
    "F1": (212.847, 238.886), "F2": (212.847, 345.226), "F3": (212.847, 105.206), "F4": (212.847, 135.346),
}
SPS_TABLE_EPOCH_UTC = datetime(1993, 7, 1, tzinfo=timezone.utc)
GPS_GHA_DEG = (18.0 + 36.0 / 60.0 + 14.4 / 3600.0) * 15.0
GPS_A = 26559.7e3
GPS_INC = 55.0 * DEG

BDS_MEO_A = R_EARTH + 21528.0e3
BDS_GEO_A = R_EARTH + 35786.0e3
BDS_INC = 55.0 * DEG
BDS3_MEO_PRNS = list(range(19, 31)) + list(range(32, 38)) + list(range(41, 47))
BDS_GEO_LON = {1: 140.0, 2: 80.0, 3: 110.5, 4: 160.0, 5: 58.75, 59: 140.0, 60: 80.0, 61: 110.5}
# IGSO: PRN -> (equator-crossing longitude deg, argument of latitude at the reference epoch deg)
BDS_IGSO = {6: (118.0, 0.0), 7: (118.0, 120.0), 8: (118.0, 240.0), 9: (95.0, 0.0), 10: (95.0, 180.0),
            38: (118.0, 0.0), 39: (118.0, 120.0), 40: (118.0, 240.0)}
# BDS-2 MEO in the same Walker pattern: PRN -> (plane, slot)
BDS2_MEO = {11: (0, 0), 12: (0, 1), 13: (1, 0), 14: (1, 1)}
BDS_REF = (BDS.week_offset, BDS.time_offset_s)  # BDT origin, 2006-01-01 00:00 UTC, as GPS (week, sow)
GST_REF = (1024, 0.0)                           # GST origin, 1999-08-22 00:00 GPST (GPS week 1024)
GAL_A = 29600.318e3
GAL_INC = 56.0 * DEG
GLO_PERIOD_S = 11 * 3600.0 + 15 * 60.0 + 44.0   # ICD nominal draconic period, 11 h 15 min 44 s
GLO_A = (glonass.MU * (GLO_PERIOD_S / (2.0 * np.pi)) ** 2) ** (1.0 / 3.0)  # Kepler's third law: 25,508 km
GLO_INC = 64.8 * DEG
GLO_SYS = System("R", "GLONASS", glonass.MU, glonass.OMEGA_E, np.inf, 0.0, 0)
# frequency channel per slot, as the IAC assigns them (antipodal slots share one), R01..R24
GLO_CHANNELS = dict(zip([f"R{k:02d}" for k in range(1, 25)],
                        [1, -4, 5, 6, 1, -4, 5, 6, -2, -7, 0, -1, -2, -7, 0, -1, 4, -3, 3, 2, 4, -3, 3, 2]))


def _j2_node_rate(a, inc, mu):
    return -1.5 * J2 * (R_EARTH / a) ** 2 * np.sqrt(mu / a**3) * np.cos(inc)


def _walker_24_3_1(plane, slot):
    """Node longitude (rad, at the BDS reference epoch; plane A at 0) and argument of latitude of a slot."""
    return plane * 120.0 * DEG, (slot * 45.0 + plane * 15.0) * DEG


def _records(rows, system, ref_sow):
    """rows: (sat_id, a, inc, node_lon, arg_lat, mean_motion, node_rate) -> (ids, Records)."""
    p = kepler.empty_table(len(rows))
    c = kepler.COL
    for k, (_, a, inc, lon, u, n, rate) in enumerate(rows):
        p[k, [c["toe"], c["toc"], c["sqrt_a"], c["i0"], c["omega0"], c["m0"], c["omega_dot"]]] = \
            [ref_sow, ref_sow, np.sqrt(a), inc, lon, u, rate]
        p[k, c["delta_n"]] = n - np.sqrt(system.mu / a**3)
        p[k, c["mu"]], p[k, c["omega_e"]], p[k, c["rel_f"]] = system.mu, system.omega_e, system.rel_f
    return [r[0] for r in rows], p


def _gps():
    week, sow = gpstime.utc_to_gps(SPS_TABLE_EPOCH_UTC)
    rate = _j2_node_rate(GPS_A, GPS_INC, GPS.mu)
    n = 2.0 * (GPS.omega_e - rate)  # 2 revolutions per day relative to the precessing node
    rows = [(f"G{k + 1:02d}", GPS_A, GPS_INC, (raan - GPS_GHA_DEG) * DEG, u * DEG, n, rate)
            for k, (raan, u) in enumerate(GPS_SLOTS.values())]
    return week, _records(rows, GPS, sow)


def _bds(prns_meo, geo, igso):
    rate = _j2_node_rate(BDS_MEO_A, BDS_INC, BDS.mu)
    n_meo = 13.0 / 7.0 * (BDS.omega_e - rate)
    rows = []
    for prn, (plane, slot) in prns_meo.items():
        lon, u = _walker_24_3_1(plane, slot)
        rows.append((f"C{prn:02d}", BDS_MEO_A, BDS_INC, lon, u, n_meo, rate))
    for prn in geo:
        rows.append((f"C{prn:02d}", BDS_GEO_A, 0.0, BDS_GEO_LON[prn] * DEG, 0.0, BDS.omega_e, 0.0))
    for prn in igso:
        lon, u = BDS_IGSO[prn]
        rows.append((f"C{prn:02d}", BDS_GEO_A, BDS_INC, (lon - u) * DEG, u * DEG, BDS.omega_e, 0.0))
    return BDS_REF[0], _records(sorted(rows), BDS, BDS_REF[1])


def _bds3():
    meo = {prn: divmod(k, 8) for k, prn in enumerate(BDS3_MEO_PRNS)}
    return _bds(meo, (59, 60, 61), (38, 39, 40))


def _bds2():
    return _bds(BDS2_MEO, (1, 2, 3, 4, 5), (6, 7, 8, 9, 10))


def _walker(prefix, system, a, inc, planes, per_plane, phase_deg, revs, days, slot_sign=1.0):
    """A Walker constellation: plane p's node at p * 360/planes deg (plane 1 at 0 at the reference epoch), slot
    j (0-based) of plane p at argument of latitude slot_sign * j * 360/per_plane + p * phase_deg; ``revs``
    revolutions in ``days`` days relative to the J2-precessing node; ids prefix + 01.. in plane order."""
    rate = _j2_node_rate(a, inc, system.mu)
    n = revs / days * (system.omega_e - rate)
    rows = []
    for p in range(planes):
        for j in range(per_plane):
            u = slot_sign * j * 360.0 / per_plane + p * phase_deg
            rows.append((f"{prefix}{p * per_plane + j + 1:02d}", a, inc, p * 360.0 / planes * DEG, u * DEG, n, rate))
    return rows


def _gal():
    # Galileo OS SDD: Walker 24/3/1, a = 29,600.318 km, i = 56 deg, ground track repeating after 17 revolutions
    # in 10 days; plane nodes and the slot -> PRN map are ours (E01-E08 plane A, ...), reference GST week 0
    rows = _walker("E", GAL, GAL_A, GAL_INC, 3, 8, 15.0, 17.0, 10.0)
    return GST_REF[0], _records(rows, GAL, GST_REF[1])


def _glo():
    # GLONASS ICD 2008 3.1: 3 planes 120 deg apart, 8 slots 45 deg apart, planes shifted 15 deg in argument of
    # latitude, slot numbers increasing against the motion, i = 64.8 deg, 11 h 15 min 44 s period, 17 revolutions
    # in 8 days; plane 1's node at 0 deg at the reference epoch is ours. Kepler circles, not the PZ-90 integration.
    rows = _walker("R", GLO_SYS, GLO_A, GLO_INC, 3, 8, 15.0, 17.0, 8.0, slot_sign=-1.0)
    return GST_REF[0], _records(rows, GLO_SYS, GST_REF[1])


_BUILDERS = {"gps": [_gps], "bds2": [_bds2], "bds3": [_bds3], "bds": [_bds3], "gps+bds": [_gps, _bds3],
             "gal": [_gal], "glo": [_glo], "gps+bds+gal+glo": [_gps, _bds3, _gal, _glo]}
NAMES = tuple(_BUILDERS)


def nominal(name: str) -> KeplerConstellation:
    """The nominal constellation ``name`` (one of :data:`NAMES`); states are valid at every epoch."""
    key = name.strip().lower()
    if key not in _BUILDERS:
        raise DataFileError(f"nominal:{name}", f"unknown nominal constellation; expected one of "
                            f"{', '.join('nominal:' + k for k in NAMES)}")
    parts = [b() for b in _BUILDERS[key]]
    ref_week = min(w for w, _ in parts)
    ids, tables = [], []
    for week, (sat_ids, p) in parts:
        shift = (week - ref_week) * gpstime.SECONDS_PER_WEEK
        p[:, kepler.COL["toe"]] += shift
        p[:, kepler.COL["toc"]] += shift
        ids += sat_ids
        tables.append(p)
    params = np.vstack(tables)
    order = np.argsort(ids, kind="stable")
    ids = [ids[k] for k in order]
    n = len(ids)
    records = Records(params[order], np.arange(n), np.ones(n, bool), np.full(n, np.inf))
    const = KeplerConstellation(ids, records, f"nominal:{key}", ref_week, "nominal")
    const.channel = np.array([GLO_CHANNELS.get(s, 0) for s in ids], dtype=np.int64)
    return const
