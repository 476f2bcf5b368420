"""What receivers see of a constellation: light time with Earth rotation, ranges, line of sight, elevation and
azimuth, elevation mask, DOPs and visible counts. Vectorised over epochs (M) x satellites (S).

Frames: ``Geometry.sat_pos`` is the satellite position at emission time rotated about z by Omega_e * tau into the
ECEF frame *at reception time* (Sagnac / Earth-rotation correction, tau the light time); ``sat_pos_emission`` is the
same position left in the ECEF frame *of the emission epoch*, as RTKLIB's ``satposs`` returns it and as
``/gnss/sat_pos_ecef`` stores it (a user adds the Sagnac term).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import frames, gpstime
from ..earth import C_LIGHT, OMEGA_E
from .light_time import back_light_time, hermite_states, light_time_step, rotated_view
from .model import Constellation

LIGHT_TIME_ITERATIONS = 3  # each iteration shrinks the error by ~v_sat/c: 3 take 75 ms to < 1e-9 m
REFINE_S = 1e-9  # a last light-time step above this (s) re-evaluates the broadcast state (see _emission)
TAU_START_S = 0.075  # start of the iteration: about a MEO's light time (20,000 km)
RECEPTION_GRID_S = 30  # s of GPS time between the broadcast states that start the iteration (interpolated)


@dataclass
class Geometry:
    """Receiver-satellite geometry at M reception epochs for S satellites (NaN where a satellite has no state).

    ``tx_week`` (M, S) int and ``tx_sow`` (M, S) s: GPS emission time (reception minus geometric light time).
    ``sat_pos`` (M, S, 3) m and ``sat_vel`` (M, S, 3) m/s (None unless asked): satellite at emission, in the ECEF
    frame of reception. ``sat_pos_emission`` (M, S, 3) m: the same position in the ECEF frame of the emission
    epoch (unrotated; RTKLIB ``satposs`` convention, what the file's ``/gnss/sat_pos_ecef`` stores). ``sat_clock`` (M, S) s and ``sat_drift`` (M, S) s/s at emission. ``range`` (M, S) m
    geometric distance, ``tau`` (M, S) s light time, ``los`` (M, S, 3) unit vectors receiver -> satellite (ECEF),
    ``elevation`` and ``azimuth`` (M, S) rad (azimuth clockwise from north in [0, 2 pi)).
    """

    tx_week: np.ndarray
    tx_sow: np.ndarray
    sat_pos: np.ndarray
    sat_vel: np.ndarray | None
    sat_clock: np.ndarray
    sat_drift: np.ndarray | None
    range: np.ndarray
    tau: np.ndarray
    los: np.ndarray
    elevation: np.ndarray
    azimuth: np.ndarray
    sat_pos_emission: np.ndarray


def _rotate_z(vec, angle):
    """Rotate vectors (..., 3) by the frame rotation R_z(angle) (angle (...)): x' = c x + s y, y' = -s x + c y."""
    c, s = np.cos(angle), np.sin(angle)
    out = np.empty_like(vec)
    out[..., 0] = c * vec[..., 0] + s * vec[..., 1]
    out[..., 1] = -s * vec[..., 0] + c * vec[..., 1]
    out[..., 2] = vec[..., 2]
    return out


def sagnac_rotate(sat_pos: np.ndarray, receiver: np.ndarray) -> np.ndarray:
    """Satellite positions (M, S, 3) m ECEF of the emission epoch rotated about z by Omega_e * tau into the ECEF
    frame of reception, tau = |sat_pos - receiver| / c the travel time to ``receiver`` (M, 3) m ECEF (one step:
    the rotation moves a satellite by ~130 m, which changes tau by < 0.5 us and the angle by < 4e-11 rad)."""
    tau = np.linalg.norm(sat_pos - receiver[:, None, :], axis=-1) / C_LIGHT
    return _rotate_z(sat_pos, OMEGA_E * tau)


def receiver_view(const: Constellation, rx_pos, gps_week, gps_sow, velocity: bool = False,
                  reception_grid: bool = False) -> Geometry:
    """Emission times by light-time iteration with Earth rotation, for receivers at ``rx_pos`` (M, 3) m ECEF at
    reception times (``gps_week`` scalar or (M,), ``gps_sow`` (M,) s GPS). Returns a :class:`Geometry`.

    ``reception_grid``: start the iteration from states interpolated on a 30 s grid of GPS time
    (:func:`_reception_states`: for epochs a second apart, half the orbit evaluations); meant for dense epochs (a
    receiver's run at 1 Hz or faster), not for sparse ones, where the grid would need more states than the epochs."""
    rx = np.atleast_2d(np.asarray(rx_pos, dtype=float))
    sow = np.atleast_1d(np.asarray(gps_sow, dtype=float))
    week = np.broadcast_to(np.asarray(gps_week), sow.shape)
    m, s = sow.size, len(const.sat_ids)
    if rx.shape != (m, 3):
        rx = np.broadcast_to(rx, (m, 3))
    week_ms = np.broadcast_to(week[:, None], (m, s))
    tau, tw, ts, out = _emission(const, rx, week_ms, sow, velocity, reception_grid)
    lla = frames.ecef_to_lla(rx)
    pos, vel, rng, los, el, az = rotated_view(out[0], out[2] if velocity else None, rx, tau,
                                              frames.ecef_to_enu_matrix(lla[:, 0], lla[:, 1]))
    return Geometry(
        tx_week=np.asarray(tw), tx_sow=np.where(np.isfinite(rng), ts, np.nan), sat_pos=pos,
        sat_vel=vel, sat_clock=out[1],
        sat_drift=out[3] if velocity else None, range=rng, tau=rng / C_LIGHT, los=los, elevation=el, azimuth=az,
        sat_pos_emission=out[0],
    )


def _emission(const, rx, week_ms, sow, velocity, reception_grid=False):
    """Light time tau (M, S) s, emission time (week, sow) and the satellite states there (``state_each``'s
    returns, with velocity and drift), for receivers ``rx`` (M, 3) at reception times.

    Two broadcast evaluations instead of a fixed-point iteration on full states: the state at reception,
    moved back along its velocity (X(t - tau) ~ X(t) - V tau, ~1 m/s^2 x tau^2 / 2 < 3 mm off), gives a light time
    within 1e-11 s; the state evaluated there (with velocity) is then moved by the last light-time step
    d = tau' - tau along its own velocity and clock drift (|d| < 1e-11 s: the neglected acceleration term is
    below 1e-21 m). Entries whose step is still above :data:`REFINE_S` (no state at reception, near the
    end of a record's validity) are evaluated again at the new time, at most LIGHT_TIME_ITERATIONS times."""
    if reception_grid:
        now = _reception_states(const, week_ms, sow)
    else:
        now = const.state_each(week_ms, np.broadcast_to(sow[:, None], week_ms.shape), velocity=True)[::2]
    tau = back_light_time(*now, rx, TAU_START_S, LIGHT_TIME_ITERATIONS)
    tw, ts = gpstime.add_seconds(week_ms, sow[:, None], -tau)
    out = [np.array(x) for x in const.state_each(tw, ts, velocity=True)]
    for i in range(LIGHT_TIME_ITERATIONS + 1):
        step = light_time_step(out[0], rx, tau)
        far = np.abs(step) > REFINE_S
        if i == LIGHT_TIME_ITERATIONS or not far.any():
            break
        tau = np.where(far, tau + step, tau)
        tw, ts = gpstime.add_seconds(week_ms, sow[:, None], -tau)
        redo = const.state_each(tw, ts, velocity=True)
        for x, y in zip(out, redo):
            x[far] = y[far]
    out[0] = out[0] - out[2] * step[..., None]
    out[1] = out[1] - out[3] * step
    tau = tau + step
    tw, ts = gpstime.add_seconds(week_ms, sow[:, None], -tau)
    return tau, tw, ts, tuple(out) if velocity else (out[0], out[1])


def _reception_states(const, week_ms, sow):
    """Satellite positions and velocities (M, S, 3) at the reception times, which only start the light-time
    iteration: cubic Hermite interpolation between broadcast states on a fixed grid of GPS time, every
    :data:`RECEPTION_GRID_S` s (3e-7 m for a MEO, 3e-15 s of light time), evaluated only at the grid times that
    bracket an epoch. The grid is absolute, so an epoch's states do not depend on the other epochs of the call
    (files do not depend on the block split). A state wrong by more than c REFINE_S (a record changing between
    grid times) costs only an extra evaluation in :func:`_emission`."""
    per_week = int(gpstime.SECONDS_PER_WEEK) // RECEPTION_GRID_S
    week = week_ms[:, 0].astype(np.int64)
    node = week * per_week + np.floor(sow / RECEPTION_GRID_S).astype(np.int64)         # the grid time at or before
    nodes = np.unique(np.concatenate([node, node + 1]))
    n_week, n_sow = nodes // per_week, (nodes % per_week) * float(RECEPTION_GRID_S)
    grid = const.state_each(np.broadcast_to(n_week[:, None], (nodes.size, week_ms.shape[1])),
                            np.broadcast_to(n_sow[:, None], (nodes.size, week_ms.shape[1])), velocity=True)
    k = np.searchsorted(nodes, node)
    x = ((week - n_week[k]) * gpstime.SECONDS_PER_WEEK + (sow - n_sow[k])) / RECEPTION_GRID_S
    return hermite_states(k, x, float(RECEPTION_GRID_S), grid[0], grid[2])


def elevation_azimuth(rx_pos, los):
    """Elevation and azimuth (rad) of unit line-of-sight vectors ``los`` (M, S, 3) ECEF seen from receivers at
    ``rx_pos`` (M, 3) m ECEF (geodetic vertical, WGS-84). Azimuth clockwise from north in [0, 2 pi)."""
    return angles_from_enu(_to_enu(rx_pos, los))


def _to_enu(rx_pos, vec):
    """ECEF vectors ``vec`` (M, S, 3) in the local ENU frames (geodetic, WGS-84) of receivers ``rx_pos`` (M, 3) m."""
    lla = frames.ecef_to_lla(np.atleast_2d(rx_pos))
    c = frames.ecef_to_enu_matrix(lla[:, 0], lla[:, 1])  # (M, 3, 3)
    return np.einsum("mij,msj->msi", c, vec)


def lines_of_sight_enu(rx_pos, sat_pos):
    """Unit lines of sight receiver -> satellite (M, S, 3) in each receiver's ENU frame and their elevations (M, S)
    rad, from receivers ``rx_pos`` (M, 3) m and satellites ``sat_pos`` (M, S, 3) m, both in one ECEF frame (NaN
    where a satellite has no position or coincides with the receiver)."""
    d = np.asarray(sat_pos, dtype=float) - np.asarray(rx_pos, dtype=float)[:, None, :]
    with np.errstate(invalid="ignore"):
        e = _to_enu(rx_pos, d / np.linalg.norm(d, axis=-1, keepdims=True))
    return e, angles_from_enu(e)[0]


def angles_from_enu(enu):
    """Elevation and azimuth (rad) of unit vectors ``enu`` (..., 3) in a local ENU frame; azimuth clockwise
    from north in [0, 2 pi)."""
    el = np.arcsin(np.clip(enu[..., 2], -1.0, 1.0))
    az = frames.wrap_2pi(np.arctan2(enu[..., 0], enu[..., 1]))
    return el, az


def visible(elevation, mask: float = 0.0):
    """Boolean (M, S): satellite has a state and is at or above the elevation ``mask`` (rad)."""
    el = np.asarray(elevation)
    return np.isfinite(el) & (el >= mask)


def visible_count(elevation, mask: float = 0.0):
    """Number of satellites (M,) at or above the elevation ``mask`` (rad)."""
    return visible(elevation, mask).sum(axis=-1)


def dops(elevation, azimuth, mask: float = 0.0, system=None) -> dict[str, np.ndarray]:
    """Dilutions of precision per epoch from elevation/azimuth (M, S) rad for satellites above ``mask`` (rad).

    Unknowns: east, north, up and one receiver clock, or one clock per system when ``system`` ((S,) letters)
    is given (a system with no visible satellite at an epoch then drops out). Returns {'G','P','H','V','T'}
    -> (M,) arrays: GDOP = sqrt(trace Q), PDOP = sqrt(Qee+Qnn+Quu), HDOP = sqrt(Qee+Qnn), VDOP = sqrt(Quu),
    TDOP = sqrt(Q of the first clock: the first system in sorted order). NaN with too few satellites.
    """
    el = np.asarray(elevation, dtype=float)
    az = np.asarray(azimuth, dtype=float)
    vis = visible(el, mask)
    systems = np.unique(system) if system is not None else np.array(["*"])
    sys_arr = np.asarray(system) if system is not None else np.full(el.shape[-1], "*")
    k = 3 + systems.size
    h = np.zeros(el.shape + (k,))
    ce = np.cos(np.where(vis, el, 0.0))
    h[..., 0] = -ce * np.sin(np.where(vis, az, 0.0))
    h[..., 1] = -ce * np.cos(np.where(vis, az, 0.0))
    h[..., 2] = -np.sin(np.where(vis, el, 0.0))
    for j, code in enumerate(systems):
        h[..., 3 + j] = sys_arr == code
    h *= vis[..., None]
    n = np.einsum("msi,msj->mij", h, h)
    absent = np.einsum("mii->mi", n)[:, 3:] == 0
    n[:, np.arange(3, k), np.arange(3, k)] += absent
    unknowns = 3 + (~absent).sum(axis=-1)
    ok = vis.sum(axis=-1) >= unknowns
    n[~ok] = np.eye(k)
    q = np.linalg.inv(n)
    d = np.einsum("mii->mi", q)
    clocks = np.where(absent, 0.0, d[:, 3:])
    out = {
        "G": np.sqrt(d[:, :3].sum(-1) + clocks.sum(-1)),
        "P": np.sqrt(d[:, :3].sum(-1)),
        "H": np.sqrt(d[:, :2].sum(-1)),
        "V": np.sqrt(d[:, 2]),
        "T": np.sqrt(np.where(absent[:, 0], np.nan, d[:, 3])),
    }
    for key in out:
        out[key] = np.where(ok, out[key], np.nan)
    return out
