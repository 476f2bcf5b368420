"""The horizon profile of a real station: an elevation mask over azimuth inferred from what the receiver tracked.

A station's horizon is rarely flat: a roof edge, a mast or a hill hides satellites below a few degrees in some
directions and not in others, and one elevation mask for every azimuth either tracks satellites the receiver
cannot see or drops ones it sees. The profile is found per azimuth sector (``SECTOR_DEG`` wide, azimuth
clockwise from north) from the satellite-epochs above the station's lowest tracked elevation: the threshold that
misclassifies the fewest of them (tracked below it plus not tracked above it; the lowest such threshold, halfway
between two observed elevations), the floor where a sector holds no satellite-epoch. It is written as a mask table
(:func:`mask_table`) that the simulator honours as ``[[environment.body_mask]]`` of a static, level antenna facing
north (body azimuth = azimuth), and evaluated with the same interpolation (:func:`simkit.environment.body
.mask_elevation`), so the twin masks exactly what :func:`below` says.

The in-sample agreement of a profile with the data it was fitted on is optimistic; :func:`holdout` fits on one
half of the epochs and checks on the other, both ways.
"""
from __future__ import annotations

import numpy as np

from ..environment.body import MaskTable, mask_elevation

SECTOR_DEG = 10.0
_EDGE_DEG = 0.01    # the table's two points per sector sit this far inside its edges (a step profile)


def profile(el, az, tracked, floor_rad: float, sector_deg: float = SECTOR_DEG, simulated=None) -> np.ndarray:
    """Mask elevation (K,) rad per azimuth sector [k sector, (k + 1) sector) deg, K = 360 / ``sector_deg``, from
    elevations ``el`` and azimuths ``az`` (rad, any shape, NaN without orbit) and whether the receiver tracked
    each satellite-epoch (``tracked``, bool, same shape); only satellite-epochs at or above ``floor_rad`` count,
    and with ``simulated`` (bool, same shape: the twin tracks it without a profile) only those tracked by one of
    the two (a satellite the twin does not simulate, unhealthy or without a signal of the file, says nothing
    about the horizon)."""
    el, az, tracked = (np.ravel(np.asarray(x)) for x in (el, az, tracked))
    k_all = int(round(360.0 / sector_deg))
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(el) & np.isfinite(az) & (el >= floor_rad)
    if simulated is not None:
        ok &= tracked | np.ravel(simulated)
    sector = (np.degrees(np.mod(az[ok], 2 * np.pi)) // sector_deg).astype(int) % k_all
    out = np.full(k_all, float(floor_rad))
    for k in np.unique(sector):
        e, on = el[ok][sector == k], tracked[ok][sector == k]
        out[k] = _best_threshold(e, on, floor_rad)
    return out


def _best_threshold(e, on, floor_rad) -> float:
    """The lowest threshold h >= floor minimising #(tracked, e < h) + #(not tracked, e >= h)."""
    order = np.argsort(e, kind="stable")
    e, on = e[order], on[order]
    cand = np.concatenate([[floor_rad], 0.5 * (e[1:] + e[:-1])[np.diff(e) > 0], [e[-1] + 1e-6]])
    tracked_below = np.searchsorted(e[on], cand, side="left")
    untracked_above = (~on).sum() - np.searchsorted(e[~on], cand, side="left")
    return float(cand[np.argmin(tracked_below + untracked_above)])


def mask_table(mask_rad, sector_deg: float = SECTOR_DEG) -> dict:
    """The profile as the keys of one ``[[environment.body_mask]]`` table (degrees, azimuth increasing in
    [0, 360)): two points per sector, just inside its edges."""
    k = np.arange(len(mask_rad))
    az = np.column_stack([k * sector_deg + _EDGE_DEG, (k + 1) * sector_deg - _EDGE_DEG]).ravel()
    el = np.repeat(np.degrees(mask_rad), 2)
    return {"azimuth_deg": [round(float(a), 4) for a in az], "elevation_deg": [round(float(x), 4) for x in el]}


def below(el, az, table: dict) -> np.ndarray:
    """Where satellites at ``el``, ``az`` (rad) are below the mask ``table`` (:func:`mask_table`), as the
    simulator's body mask decides it for a level antenna facing north."""
    tab = MaskTable(np.radians(table["azimuth_deg"]), np.radians(table["elevation_deg"]), None)
    with np.errstate(invalid="ignore"):
        return np.asarray(el) < mask_elevation(tab, np.nan_to_num(az))


def agreement(el, az, real_on, twin_on, floor_rad: float, table: dict | None, rows=None) -> dict:
    """Visibility agreement over the satellite-epochs above ``floor_rad`` (rows ``rows`` only, default all) when
    the twin's tracking ``twin_on`` (without the profile) is cut by the profile ``table``."""
    rows = slice(None) if rows is None else rows
    el, az, real_on, twin_on = el[rows], az[rows], real_on[rows], twin_on[rows]
    pred = twin_on & ~below(el, az, table) if table is not None else twin_on
    with np.errstate(invalid="ignore"):
        above = el >= floor_rad
    return {"agreement": float(np.mean(real_on[above] == pred[above])) if above.any() else None,
            "satellite_epochs": int(above.sum()),
            "real_not_twin": int((real_on & ~pred & above).sum()),
            "twin_not_real": int((pred & ~real_on & above).sum())}


def holdout(el, az, real_on, twin_on, floor_rad: float, sector_deg: float = SECTOR_DEG) -> dict:
    """The profile fitted on the first half of the epochs and checked on the second, and the other way round:
    {"first->second": agreement dict, "second->first": ...} (:func:`agreement`)."""
    m = el.shape[0]
    halves = (np.arange(m) < m // 2, np.arange(m) >= m // 2)
    out = {}
    for name, fit_rows, check_rows in (("first->second", *halves), ("second->first", *halves[::-1])):
        prof = profile(el[fit_rows], az[fit_rows], real_on[fit_rows], floor_rad, sector_deg, twin_on[fit_rows])
        out[name] = agreement(el, az, real_on, twin_on, floor_rad, mask_table(prof, sector_deg), check_rows)
    return out
