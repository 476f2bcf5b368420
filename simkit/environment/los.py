"""Line-of-sight state per antenna, satellite and epoch: direct, direct plus reflection, reflection only (NLOS),
blocked, or below the horizon; with the tracked reflection's extra path and its rate.

Geometry is planar in the trajectory origin's local frame: an antenna's east and north come from the origin's
ENU axes, its height is its ellipsoidal height above the origin's (walls stand on a flat street), and the
directions to the satellites are the antenna's own azimuth and elevation (routes of a few km: the frames differ by
well under a milliradian). Buildings and canyons give walls (:mod:`.raycast`); body masks are tested in the body
frame for the direct line of sight and for the arrival direction of the reflection.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import frames
from .body import body_blocked
from .config import EnvironmentConfig
from .raycast import trace
from .walls import build_grid

DIRECT, DIRECT_REFLECTED, NLOS, BLOCKED, BELOW_HORIZON = 0, 1, 2, 3, 255
STATE_NAMES = {DIRECT: "direct", DIRECT_REFLECTED: "direct+reflected", NLOS: "NLOS", BLOCKED: "blocked",
               BELOW_HORIZON: "below horizon"}


@dataclass(frozen=True)
class LineOfSight:
    """(M, A, C) arrays: ``state`` uint8 (the constants above); ``extra`` m the reflected path's extra length
    where a reflection is received (states 1 and 2), 0 for state 0, NaN otherwise; ``extra_rate`` m/s its
    time derivative (0 / NaN likewise); ``incidence`` rad the reflection's angle of incidence on the wall
    (from the wall normal), NaN without a reflection."""

    state: np.ndarray
    extra: np.ndarray
    extra_rate: np.ndarray
    incidence: np.ndarray


class Environment:
    """The built environment of a scenario around the origin ``origin_lla`` (lat rad, lon rad, height m),
    for antennas at lever arms ``lever_b`` (A, 3) m."""

    def __init__(self, cfg: EnvironmentConfig, origin_lla, lever_b):
        self.cfg = cfg
        self.lat0, self.lon0, self.h0 = (float(x) for x in origin_lla)
        self.origin_ecef = frames.lla_to_ecef(self.lat0, self.lon0, self.h0)
        self.c_en = frames.ecef_to_enu_matrix(self.lat0, self.lon0)
        self.lever_b = np.asarray(lever_b, dtype=float)
        w = cfg.walls
        self.grid = build_grid(w, cfg.grid_cell_m)
        self.ax, self.ay = np.ascontiguousarray(w.a[:, 0]), np.ascontiguousarray(w.a[:, 1])
        self.bx, self.by = np.ascontiguousarray(w.b[:, 0]), np.ascontiguousarray(w.b[:, 1])
        self.top = np.ascontiguousarray(w.top)

    def local(self, ant_pos_ecef, ant_lla) -> np.ndarray:
        """Antenna positions (M, A, 3) m: east, north in the origin's plane, height above the origin."""
        en = np.einsum("ij,maj->mai", self.c_en[:2], ant_pos_ecef - self.origin_ecef)
        return np.concatenate([en, ant_lla[..., 2:3] - self.h0], axis=-1)

    def classify(self, ant_pos_ecef, lla, vel_enu, los_ecef, az, el, az_rate, el_rate, c_be,
                 body: bool = True) -> LineOfSight:
        """The line-of-sight state of antennas at ``ant_pos_ecef`` (M, A, 3) m (geodetic ``lla`` (M, A, 3),
        velocity ``vel_enu`` (M, A, 3) m/s) towards satellites along unit vectors ``los_ecef`` (M, A, C, 3) at
        azimuth ``az`` and elevation ``el`` (M, A, C) rad with rates ``az_rate``, ``el_rate`` rad/s; ``c_be``
        (M, 3, 3) body -> ECEF; ``body`` False leaves the body masks out."""
        pos = np.ascontiguousarray(self.local(ant_pos_ecef, lla))
        g = self.grid
        az_c = np.ascontiguousarray(np.nan_to_num(az, nan=0.0))
        el_c = np.ascontiguousarray(np.where(np.isfinite(el), np.minimum(el, np.pi / 2 - 1e-9), -1.0))
        direct, wall, extra = trace(pos, az_c, el_c, g.x0, g.y0, g.cell, g.nx, g.ny, g.start, g.walls,
                                    self.ax, self.ay, self.bx, self.by, self.top, self.cfg.reflection_range_m,
                                    self.cfg.reflections)
        has = wall >= 0
        n, d = self._normal(wall, pos)                                         # (M, A, C, 2), (M, A, C)
        sa, ca, se, ce = np.sin(az_c), np.cos(az_c), np.sin(el_c), np.cos(el_c)
        nu = ce * (n[..., 0] * sa + n[..., 1] * ca)
        if body and (self.cfg.mask_tables or self.cfg.boxes):
            c_eb = np.swapaxes(c_be, -1, -2)
            direct |= body_blocked(self.cfg.mask_tables, self.cfg.boxes, self.lever_b,
                                   np.einsum("mij,macj->maci", c_eb, los_ecef))
            mirror = np.stack([ce * sa - 2 * nu * n[..., 0], ce * ca - 2 * nu * n[..., 1], se], axis=-1)
            c_ne = np.swapaxes(frames.ecef_to_enu_matrix(lla[..., 0], lla[..., 1]), -1, -2)   # (M, A, 3, 3)
            mirror_e = np.einsum("maij,macj->maci", c_ne, mirror)
            has &= ~body_blocked(self.cfg.mask_tables, self.cfg.boxes, self.lever_b,
                                 np.einsum("mij,macj->maci", c_eb, mirror_e))
        up = el_c > 0.0
        state = np.where(~direct, np.where(has, DIRECT_REFLECTED, DIRECT), np.where(has, NLOS, BLOCKED))
        state = np.where(up, state, BELOW_HORIZON).astype(np.uint8)
        # d/dt [2 d (n.u)]: d' = n . v_h (walls fixed), (n.u)' = n . du_h/dt
        du_e = -se * sa * el_rate + ce * ca * az_rate
        du_n = -se * ca * el_rate - ce * sa * az_rate
        nv = n[..., 0] * vel_enu[:, :, None, 0] + n[..., 1] * vel_enu[:, :, None, 1]
        rate = 2.0 * nv * nu + 2.0 * d * (n[..., 0] * du_e + n[..., 1] * du_n)
        has = np.isin(state, (DIRECT_REFLECTED, NLOS))
        zero = state == DIRECT
        extra = np.where(has, extra, np.where(zero, 0.0, np.nan))
        rate = np.where(has, rate, np.where(zero, 0.0, np.nan))
        incidence = np.where(has, np.arccos(np.clip(nu, -1.0, 1.0)), np.nan)
        return LineOfSight(state, extra, rate, incidence)

    def _normal(self, wall, pos):
        """Unit normals (..., 2) of the walls ``wall`` towards the antennas at ``pos`` (M, A, 3) and the
        antennas' distances (...) m to the walls' planes (zeros where ``wall`` is -1)."""
        w = np.maximum(wall, 0)
        if self.top.size == 0:
            return np.zeros(wall.shape + (2,)), np.zeros(wall.shape)
        ex, ey = self.bx[w] - self.ax[w], self.by[w] - self.ay[w]
        length = np.hypot(ex, ey)
        n = np.stack([ey / length, -ex / length], axis=-1)
        d = (n[..., 0] * (pos[:, :, None, 0] - self.ax[w]) + n[..., 1] * (pos[:, :, None, 1] - self.ay[w]))
        sign = np.where(d < 0, -1.0, 1.0)
        ok = wall >= 0
        return np.where(ok[..., None], n * sign[..., None], 0.0), np.where(ok, d * sign, 0.0)

    def static(self, site_ecef, az, el) -> LineOfSight:
        """The states seen by a fixed antenna at ``site_ecef`` (3,) m towards satellites at azimuth ``az`` and
        elevation ``el`` (T, S) rad (body masks do not apply: there is no vehicle)."""
        t_n, s_n = np.shape(az)
        pos = np.broadcast_to(np.asarray(site_ecef, dtype=float), (t_n, 1, 3))
        lla = np.broadcast_to(frames.ecef_to_lla(np.asarray(site_ecef, dtype=float)[None])[0], (t_n, 1, 3))
        zeros = np.zeros((t_n, 1, s_n))
        return self.classify(pos, lla, np.zeros((t_n, 1, 3)), np.zeros((t_n, 1, s_n, 3)), np.asarray(az)[:, None],
                             np.asarray(el)[:, None], zeros, zeros, np.broadcast_to(np.eye(3), (t_n, 3, 3)),
                             body=False)
