"""A trajectory from a recorded log: a P-spline (:mod:`.pspline`) through the logged positions, and exact truth
from its derivatives.

The positions are fitted per axis in the local tangent frame L (ENU at the first used sample, fixed to the
Earth: an exact affine image of ECEF), so position, velocity, acceleration and jerk relative to the Earth are
the spline's derivatives mapped to ECEF. From them, at any time:

- geodetic position, and v^n = C_e^n v^e; the ENU frame turns at w_en^n (transport rate), so
  dv^n/dt = C_e^n a^e - w_en^n x v^n;
- attitude by one of three rules: "log" (pitch, roll and unwrapped heading each P-spline-fitted, their rates the
  spline derivatives); "ground" (body y along the velocity, no side-slip, roll 0: heading atan2(vE, vN), pitch
  atan2(vU, v_h)); "coordinated" (as "ground", with the bank of a coordinated turn, atan(q / g0) where
  q = ((a^e x v^e) . u^e) / v_h is the lateral acceleration about the ellipsoid normal u, the analytic
  generator's V psi' cos(gamma) up to the tiny transport-rate term); every rate is formed in closed form from
  the velocity, acceleration and jerk;
- w_ib^b = w_nb^b (from the Euler rates, as in :mod:`.generator`) + C_n^b (w_ie^n + w_en^n), and
  f^b = C_n^b (dv^n/dt + (2 w_ie^n + w_en^n) x v^n - g^n) with WGS-84 normal gravity.

So an RK4 strapdown of the stored rates reproduces the stored truth, as for the analytic segments.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import earth, frames
from ..earth import G0
from ..errors import DataFileError
from .truth import TrajectoryTruth, body_truth, trig

ATTITUDE_RULES = ("log", "ground", "coordinated")
MIN_POINTS = 4
MIN_SPEED_M_PER_S = 1.0            # the velocity-following rules need a direction of motion
HELD_SIGMA_RAD = 1e-3              # ground rule through stops: the angles are fitted to ~0.06 deg at >= 5 m/s
HELD_SPEED_M_PER_S = 5.0           # below it a heading sample's sigma grows as 1 / speed (noise turns it more)
_SIGMA_FLOOR_M = 1e-3              # an exact (noise-free) log still gets finite weights
_SIGMA_FLOOR_RAD = 1e-6


@dataclass(frozen=True)
class Track:
    """K logged samples: ``t`` (K,) s since the scenario start (GPS time); ``pos_ecef`` (K, 3) m; optional
    ``sigma_enu`` (K, 3) m position standard deviations; ``vel_enu`` (K, 3) m/s (NaN where a component is not
    logged) with ``sigma_vel`` (K, 3) m/s; ``euler`` (K, 3) rad [pitch, roll, heading]; ``line`` (K,) the line or
    record of each sample in ``source`` (for messages)."""

    t: np.ndarray
    pos_ecef: np.ndarray
    line: np.ndarray
    source: str
    sigma_enu: np.ndarray | None = None
    vel_enu: np.ndarray | None = None
    sigma_vel: np.ndarray | None = None
    euler: np.ndarray | None = None

    def take(self, index) -> "Track":
        f = lambda a: None if a is None else a[index]
        return Track(self.t[index], self.pos_ecef[index], self.line[index], self.source, f(self.sigma_enu),
                     f(self.vel_enu), f(self.sigma_vel), f(self.euler))


@dataclass(frozen=True, kw_only=True)
class FitOptions:
    """How a log is fitted (the ``[trajectory]`` keys of docs/logs_and_export.md, in SI units)."""

    position_sigma_m: tuple | None = None      # (e, n, u); None: the log's own, else estimated
    velocity_sigma_m_per_s: float | None = None
    attitude: str | None = None                # None: "log" when the log has attitude, else "ground"
    attitude_sigma_rad: float | None = None
    max_gap_s: float = 10.0
    max_speed_m_per_s: float = 500.0
    outliers: str = "refuse"                   # "refuse": a jump is an error; "drop": its outlying samples go


def check(track: Track, opts: FitOptions) -> None:
    """Refuse a log that cannot be a trajectory (too few samples, time not increasing, a gap above the limit):
    one DataFileError naming the file and line."""
    src = track.source
    if len(track.t) < MIN_POINTS:
        raise DataFileError(src, f"{len(track.t)} usable samples in the scenario's time span, need at least "
                                 f"{MIN_POINTS}")
    if not (np.all(np.isfinite(track.t)) and np.all(np.isfinite(track.pos_ecef))):
        bad = int(np.nonzero(~np.isfinite(track.pos_ecef).all(1) | ~np.isfinite(track.t))[0][0])
        raise DataFileError(src, "position or time is not a finite number", int(track.line[bad]))
    dt = np.diff(track.t)
    if np.any(dt <= 0):
        k = int(np.nonzero(dt <= 0)[0][0])
        raise DataFileError(src, f"time does not increase ({track.t[k + 1] - track.t[k]:+.3f} s after the "
                                 f"sample of line {track.line[k]}): expected strictly increasing time", int(track.line[k + 1]))
    if np.any(dt > opts.max_gap_s):
        k = int(np.nonzero(dt > opts.max_gap_s)[0][0])
        raise DataFileError(src, f"gap of {dt[k]:.1f} s before this sample (after line {track.line[k]}) is longer "
                                 f"than trajectory.max_gap_s = {opts.max_gap_s:g}: raise it to bridge the gap, or "
                                 f"select a part of the log with scenario.start / duration_s", int(track.line[k + 1]))


def _enu_axes(track: Track) -> np.ndarray:
    """ECEF -> local ENU rotation (3, 3) at the track's first sample: the axes of the jump test."""
    lla = frames.ecef_to_lla(track.pos_ecef[0])
    return frames.ecef_to_enu_matrix(lla[0], lla[1])


def _jumps(t, pos_ecef, c_enu, opts: FitOptions, sigma_m) -> np.ndarray:
    """Indices k of the steps k -> k + 1 (times ``t`` s, positions (K, 3) m ECEF) faster than
    ``max_speed_m_per_s`` plus 6 sigma of noise on some local axis (``c_enu`` ECEF -> ENU; ``sigma_m`` a scalar
    or per axis (3,) m)."""
    step = np.abs(np.diff(pos_ecef, axis=0) @ c_enu.T)
    allowed = opts.max_speed_m_per_s * np.diff(t)[:, None] + 6.0 * np.sqrt(2.0) * np.asarray(sigma_m, float)
    return np.flatnonzero((step > allowed).any(axis=1))


_JUMP_WINDOW = 512


def drop_jumps(track: Track, opts: FitOptions, sigma_m) -> tuple[Track, np.ndarray]:
    """The track without its outlying samples, and their lines: while a step is too fast, of its two ends the one
    farther from the median position of its 8 neighbours (4 either side, itself excluded) is dropped.

    The steps are scanned in windows: dropping a sample changes only the step into its place, so the scan goes on
    from the step before it, and a log with m outliers costs O(K + m * window), not O(K * m)."""
    kept, dropped, p = np.arange(len(track.t)), [], 0      # steps before kept[p] are known to be good
    c_enu = _enu_axes(track)
    while p < len(kept) - 1:
        seg = kept[p:p + _JUMP_WINDOW + 1]
        bad = _jumps(track.t[seg], track.pos_ecef[seg], c_enu, opts, sigma_m)
        if bad.size == 0:
            p += _JUMP_WINDOW
            continue
        k = p + int(bad[0])
        dev = []
        for j in (k, k + 1):
            near = kept[np.r_[max(0, j - 4):j, j + 1:min(len(kept), j + 5)]]
            dev.append(np.linalg.norm(track.pos_ecef[kept[j]] - np.median(track.pos_ecef[near], axis=0)))
        j = k if dev[0] > dev[1] else k + 1
        dropped.append(int(track.line[kept[j]]))
        kept = np.delete(kept, j)
        p = max(0, k - 1)
    return track.take(kept), np.asarray(dropped, dtype=np.int64)


def check_jumps(track: Track, opts: FitOptions, sigma_m) -> None:
    """Refuse a step between samples faster than ``max_speed_m_per_s`` plus 6 sigma of noise (``sigma_m`` (3,)
    m per local axis) on some axis."""
    src, dt = track.source, np.diff(track.t)
    step = np.linalg.norm(np.diff(track.pos_ecef, axis=0), axis=1)
    bad = _jumps(track.t, track.pos_ecef, _enu_axes(track), opts, sigma_m)
    if bad.size:
        k = int(bad[0])
        raise DataFileError(src, f"jump of {step[k]:.1f} m in {dt[k]:.3g} s ({step[k] / dt[k]:.0f} m/s) from line "
                                 f"{track.line[k]}, above trajectory.max_speed_m_per_s = {opts.max_speed_m_per_s:g} "
                                 f"(plus 6 sigma of noise)", int(track.line[k + 1]))


def _pspline():
    """:mod:`.pspline`, imported on first use: its scipy modules cost every run 0.2 s, and only a logged trajectory
    needs them."""
    from . import pspline

    return pspline


def _sigmas(track, local, opts):
    """Per-sample position sigmas (K, 3) and the per-axis figure used (stated, logged or estimated)."""
    if opts.position_sigma_m is not None:
        sig = np.broadcast_to(np.asarray(opts.position_sigma_m, float), local.shape).copy()
        how = "stated"
    elif track.sigma_enu is not None and np.all(np.isfinite(track.sigma_enu)):
        sig, how = np.array(track.sigma_enu, float), "logged"
    else:
        est = np.array([_pspline().noise_sigma(track.t, local[:, i]) for i in range(3)])
        if not np.all(np.isfinite(est)):
            raise DataFileError(track.source, "cannot estimate the position noise (no runs of evenly spaced "
                                              "samples): give trajectory.position_sigma_m")
        sig, how = np.broadcast_to(est, local.shape).copy(), "estimated"
    return np.maximum(sig, _SIGMA_FLOOR_M), how


class LoggedPath:
    """The fitted trajectory; :meth:`truth` evaluates it at any times inside [0, duration]."""

    def __init__(self, track: Track, opts: FitOptions, duration_s: float):
        self.source = track.source
        self.rule = opts.attitude or ("log" if track.euler is not None else "ground")
        if self.rule == "log" and track.euler is None:
            raise DataFileError(track.source, "trajectory.attitude = 'log' but the log has no attitude")
        check(track, opts)
        lla0 = frames.ecef_to_lla(track.pos_ecef[0])
        self.r0 = track.pos_ecef[0].copy()
        self.c_le = frames.ecef_to_enu_matrix(lla0[0], lla0[1]).T          # L (ENU at r0) -> ECEF
        local = (track.pos_ecef - self.r0) @ self.c_le
        sig, self.sigma_source = _sigmas(track, local, opts)
        self.sigma_m = np.sqrt(np.mean(sig**2, axis=0))
        self.dropped = np.zeros(0, dtype=np.int64)
        if opts.outliers == "drop":
            t_all = track.t
            track, self.dropped = drop_jumps(track, opts, self.sigma_m)
            kept = np.searchsorted(t_all, track.t)
            local, sig = local[kept], sig[kept]
            check(track, opts)
        check_jumps(track, opts, self.sigma_m)
        t = track.t
        if t[0] > 1e-9 or t[-1] < duration_s - 1e-9:
            raise DataFileError(track.source, f"the log covers {t[0]:.3f} s to {t[-1]:.3f} s from scenario.start, "
                                              f"but the run needs 0 to {duration_s:g} s: move scenario.start or "
                                              f"shorten scenario.duration_s")
        spacing = float(np.median(np.diff(t)))
        self.knots = _pspline().knots(t[0], t[-1], spacing)
        self._fit_positions(track, local, sig, opts)
        self.att_splines = None
        if self.rule == "log":
            self._fit_attitude(track, opts)
        else:
            grid = np.linspace(0.0, duration_s, max(2, int(np.ceil(duration_s / min(spacing, 0.1))) + 1))
            vmin, k = self._slowest(grid)
            if vmin < MIN_SPEED_M_PER_S and self.rule == "ground":
                self._hold_through_stops(track.t, opts)
            elif vmin < MIN_SPEED_M_PER_S:   # the coordinated rule banks by the turn rate: no direction, no bank
                raise DataFileError(self.source, f"the fitted path slows to {vmin:.2f} m/s at {grid[k]:.1f} s: "
                                                 f"attitude rule {self.rule!r} needs a horizontal speed of at "
                                                 f"least {MIN_SPEED_M_PER_S:g} m/s (give attitude in the log, or "
                                                 f"select a moving part with scenario.start / duration_s)")

    def _local_velocity(self, track: Track, opts: FitOptions):
        """Logged velocities in L and their sigmas (K, 3), or (None, None) when absent or of unknown accuracy."""
        sv = opts.velocity_sigma_m_per_s
        if track.vel_enu is None or (sv is None and track.sigma_vel is None):
            return None, None            # a logged velocity without a stated accuracy is not used (documented)
        lla = frames.ecef_to_lla(track.pos_ecef)
        vel_l = frames.enu_to_ecef_vec(np.nan_to_num(track.vel_enu), lla[:, 0], lla[:, 1]) @ self.c_le
        vel_l[~np.isfinite(track.vel_enu)] = np.nan      # the axes stay near-aligned over a log's extent
        return vel_l, (np.full(vel_l.shape, sv) if sv is not None else track.sigma_vel)

    def _fit_positions(self, track, local, sig, opts):
        t = track.t
        vel_l, sig_v = self._local_velocity(track, opts)
        self.splines, self.lam, self.chi2 = [], [], []
        for i in range(3):
            kw = {}
            ok = np.isfinite(vel_l[:, i]) if vel_l is not None else np.zeros(len(t), bool)
            if ok.any():                         # (RMC and VTG give no vertical velocity)
                kw = dict(xv=t[ok], v=vel_l[ok, i], sigma_v=np.maximum(sig_v[ok, i], 1e-4))
            s, lam, chi2 = _pspline().smooth(self.knots, t, local[:, i], sig[:, i], **kw)
            self.splines.append(s)
            self.lam.append(lam)
            self.chi2.append(chi2)
        self.residual_rms_m = np.sqrt(np.mean((np.stack([s(t) for s in self.splines], -1) - local) ** 2, axis=0))

    def _fit_attitude(self, track, opts):
        angles = np.array(track.euler, float)
        angles[:, 2] = np.unwrap(angles[:, 2])
        self.att_splines = []
        for i in range(3):
            sa = opts.attitude_sigma_rad or _pspline().noise_sigma(track.t, angles[:, i])
            sa = max(sa if np.isfinite(sa) else 0.0, _SIGMA_FLOOR_RAD)
            self.att_splines.append(_pspline().smooth(self.knots, track.t, angles[:, i], np.full(len(track.t), sa))[0])

    def _slowest(self, grid):
        """(the lowest horizontal speed of the fitted path on ``grid`` (m/s), its index)."""
        v = np.stack([s(grid, 1) for s in self.splines], -1)
        vh = np.hypot(v[:, 0], v[:, 1])          # the tangent plane's horizontal, to within the log's extent
        return float(vh.min()), int(np.argmin(vh))

    def _hold_through_stops(self, t, opts):
        """Ground rule with stops: the heading and pitch of the fitted velocity at the log's epochs where it moves
        at half HELD_SPEED_M_PER_S or more (slower, the fit's lateral wander of a few cm turns it by degrees), carried (linearly in heading) through the slower epochs, then fitted by the
        same smoothing spline as logged angles (sigma ``HELD_SIGMA_RAD``, growing as 1 / speed below
        ``HELD_SPEED_M_PER_S``), so the attitude and its rates stay smooth and exact through a stop; roll zero."""
        v = np.stack([s(t, 1) for s in self.splines], -1)
        vh = np.hypot(v[:, 0], v[:, 1])
        moving = vh >= 0.5 * HELD_SPEED_M_PER_S
        if moving.sum() < 2:
            raise DataFileError(self.source, f"the fitted path never moves at {0.5 * HELD_SPEED_M_PER_S:g} m/s or "
                                             f"more on two epochs: attitude rule 'ground' has no direction to hold")
        heading = np.unwrap(np.arctan2(v[moving, 0], v[moving, 1]))
        pitch = np.arctan2(v[moving, 2], vh[moving])
        angles = np.stack([np.interp(t, t[moving], pitch), np.zeros_like(t), np.interp(t, t[moving], heading)], -1)
        sigma = HELD_SIGMA_RAD * np.where(moving, np.maximum(1.0, HELD_SPEED_M_PER_S / np.maximum(vh, 1e-9)), 1.0)
        self.att_splines = [_pspline().smooth(self.knots, t, angles[:, i], sigma)[0] for i in range(3)]
        self.held_epochs = int((~moving).sum())

    def summary(self) -> dict:
        """What the fit used and found (the ``log`` attribute of /truth): rule, sigmas and their source, residual
        RMS per axis (m), plus whatever the reader added to ``provenance`` (file, digest)."""
        return dict(getattr(self, "provenance", {}), attitude=self.rule, sigma_m=self.sigma_m.tolist(),
                    sigma_source=self.sigma_source, residual_rms_m=self.residual_rms_m.tolist(),
                    dropped_lines=self.dropped.tolist(), held_epochs=getattr(self, "held_epochs", 0))

    def truth(self, t) -> TrajectoryTruth:
        """Truth at times ``t`` (N,) s since the scenario start."""
        t = np.asarray(t, dtype=float)
        d = [np.stack([s(t, nu) for s in self.splines], -1) @ self.c_le.T for nu in range(4)]
        r_e, v_e, a_e, j_e = d
        r_e = r_e + self.r0
        lla = frames.ecef_to_lla(r_e)
        lat, hgt = lla[:, 0], lla[:, 2]
        c_en = frames.ecef_to_enu_matrix(lat, lla[:, 1])
        v_n = np.einsum("nij,nj->ni", c_en, v_e)
        w_en = earth.transport_rate_enu(lat, hgt, v_n)
        a_n = np.einsum("nij,nj->ni", c_en, a_e) - np.cross(w_en, v_n)
        if self.att_splines is not None:
            (gamma, roll, psi), (gamma_dot, roll_dot, psi_dot) = (
                [np.stack([s(t, nu) for s in self.att_splines]) for nu in (0, 1)])
        else:
            gamma, psi, gamma_dot, psi_dot, vh, vh_dot = _velocity_angles(v_n, a_n)
            if self.rule == "coordinated":
                up = c_en[:, 2, :]
                up_dot = np.cross(np.einsum("nji,nj->ni", c_en, w_en), up)
                q = np.einsum("ni,ni->n", np.cross(a_e, v_e), up) / vh
                q_dot = (np.einsum("ni,ni->n", np.cross(j_e, v_e), up)
                         + np.einsum("ni,ni->n", np.cross(a_e, v_e), up_dot)) / vh - q * vh_dot / vh
                roll = np.arctan(q / G0)
                roll_dot = G0 * q_dot / (G0**2 + q**2)
            else:
                roll = roll_dot = np.zeros_like(t)
        w_ie = earth.earth_rate_enu(lat)
        f_n = a_n + np.cross(2.0 * w_ie + w_en, v_n) - earth.gravity_enu(lat, hgt)
        quat, euler, omega, f_b = body_truth(trig(gamma), trig(roll), trig(psi), (gamma_dot, roll_dot, psi_dot),
                                             (w_ie + w_en).T, f_n.T)
        return TrajectoryTruth(t=t, pos_ecef=r_e, pos_lla=lla, vel_enu=v_n, quat_nb=quat, euler=euler,
                               omega_ib_b=omega, f_ib_b=f_b)


def _velocity_angles(v_n, a_n):
    """Heading, flight-path angle, their rates, horizontal speed and its rate from ENU velocity and its rate."""
    ve, vn, vu = v_n.T
    ae, an, au = a_n.T
    vh2 = ve**2 + vn**2
    vh = np.sqrt(vh2)
    speed2 = vh2 + vu**2
    vh_dot = (ve * ae + vn * an) / vh
    return (np.arctan2(vu, vh), np.arctan2(ve, vn), (au * vh - vu * vh_dot) / speed2,
            (vn * ae - ve * an) / vh2, vh, vh_dot)
