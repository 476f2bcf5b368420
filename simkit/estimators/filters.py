"""Loosely coupled INS/GNSS filters: :class:`KalmanFilter15`, :class:`KalmanFilter21`, :class:`HInfinityFilter`.

Each has ``run(imu, gnss, attitude=None) -> Solution`` on numpy arrays (``ImuData``, ``GnssFixes``,
``AttitudeFixes``), no file involved. The solution has one epoch per GNSS fix used (after its update): IMU-centre
position, velocity, attitude, the error-state covariance (``cov``, in the order of ``state_names``, SI units:
rad, m/s, rad, rad, m, rad/s, m/s^2, m, and m for the optional GNSS-error states), and extras: ``gyro_bias``
(rad/s), ``accel_bias`` (m/s^2), ``lever_arm`` (m), ``gnss_error`` (m ENU, with those states), ``nis`` with
``nis_dof`` (6; 0 where the update was skipped: the referee's NIS test) and ``innovation_std`` (standardised position/velocity innovations), ``status``,
and for H-infinity ``gamma`` and ``existence_margin`` (smallest eigenvalue of the existence matrix in the
congruent form L^T (P^-1 - theta I + H^T R^-1 H) L, P = L L^T: dimensionless, positive whenever it exists).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy.spatial.transform import Rotation
from scipy.stats import chi2

from ..frames import ecef_to_lla, euler_from_attitude, lla_to_ecef
from ..solution import Solution
from . import loop, model
from .errors import EstimatorInputError
from .increments import from_increments, from_rates, window_mean_rate
from .inputs import AttitudeFixes, DDCarrier, GnssFixes, ImuData, InitialState

STATE_NAMES = ("phi_e", "phi_n", "phi_u", "dv_e", "dv_n", "dv_u", "d_lat", "d_lon", "d_h",
               "gyro_bias_x", "gyro_bias_y", "gyro_bias_z", "accel_bias_x", "accel_bias_y", "accel_bias_z",
               "lever_x", "lever_y", "lever_z")
GNSS_ERROR_STATES = ("gnss_error_e", "gnss_error_n", "gnss_error_u")


@dataclass(frozen=True)
class FilterConfig:
    """Noise model and initial uncertainty (SI). White noise densities: ``gyro_arw`` rad/s/sqrt(Hz),
    ``accel_vrw`` m/s^2/sqrt(Hz); bias random walks ``gyro_bias_rw`` rad/s/sqrt(s), ``accel_bias_rw``
    m/s^2/sqrt(s); initial sigmas ``p0_att`` [pitch-ish E, N, U] rad, ``p0_vel`` m/s, ``p0_pos`` [E, N, U] m,
    ``p0_gyro_bias`` rad/s, ``p0_accel_bias`` m/s^2, ``p0_lever`` m (21 states); ``lever_rate_window_s`` s: the
    lever-arm rows of the velocity update take the body rate averaged over this trailing window, ending three
    samples before the fix (0: the rate at the fix's sample; see :func:`.loop._pv_rows`); ``cov_dt`` s covariance step;
    ``alpha`` H-infinity tuning (Wu 2015: 10); ``gamma_rule``
    "wu" (Wu's H^T H, with the weighted rule as fallback) or "weighted" (H^T R^-1 H);
    ``gyro_bias0``/``accel_bias0`` initial bias estimates (body); ``dd_gate_p`` (kf15_dd) rejects a DD carrier
    epoch whose NIS exceeds the chi-square(m rows) quantile 1 - dd_gate_p (0: no gate); ``update_at_start``: use
    the measurements that fall on the initial epoch (False when the initial state was built from them, as the
    "static", "motion" and "attitude" alignments of ``simkit solve`` do: they would count twice);
    ``gnss_error_sigma`` [E, N, U] m and ``gnss_error_tau`` s: the slowly varying error of the position fixes
    (broadcast orbits and clocks, ionosphere and troposphere residuals, seen through the geometry) as three
    first-order Gauss-Markov states appended to the error state (``gnss_error_e/n/u``; all sigmas 0: none). A
    filter that takes such fixes as white noise averages them down and reports a covariance far below its error."""

    gyro_arw: float = 1e-4
    accel_vrw: float = 1e-3
    gyro_bias_rw: float = 0.0
    accel_bias_rw: float = 0.0
    p0_att: tuple = (0.01, 0.01, 0.1)
    p0_vel: float = 0.1
    p0_pos: tuple = (5.0, 5.0, 10.0)
    p0_gyro_bias: float = 1e-4
    p0_accel_bias: float = 1e-2
    p0_lever: float = 0.1
    lever_rate_window_s: float = 0.1
    cov_dt: float = 0.1
    alpha: float = 10.0
    gyro_bias0: tuple = (0.0, 0.0, 0.0)
    accel_bias0: tuple = (0.0, 0.0, 0.0)
    gamma_rule: str = "wu"
    dd_gate_p: float = 0.0
    update_at_start: bool = True
    gnss_error_sigma: tuple = (0.0, 0.0, 0.0)
    gnss_error_tau: float = 1800.0


def _layout(base: int, cfg: FilterConfig) -> tuple[int, int, int]:
    """(state count, lever-arm index, GNSS-error index) of a filter with ``base`` states (15, or 18 with the lever
    arm) and ``cfg``'s optional GNSS-error states; -1 for an absent block."""
    sigma = np.broadcast_to(np.asarray(cfg.gnss_error_sigma, float), 3)
    if not (np.all(sigma >= 0) and np.isfinite(sigma).all()) or not cfg.gnss_error_tau > 0:
        raise EstimatorInputError(f"gnss_error_sigma {cfg.gnss_error_sigma!r} / gnss_error_tau "
                                  f"{cfg.gnss_error_tau!r}: expected sigmas >= 0 and a correlation time > 0")
    ib = base if np.any(sigma > 0) else -1
    return base + (3 if ib >= 0 else 0), (15 if base >= 18 else -1), ib


def _p0(cfg: FilterConfig, n: int, lat: float, h: float, il: int, ib: int) -> np.ndarray:
    tp = model.enu_to_geodetic(lat, h)
    sig = np.zeros(n)
    sig[0:3] = np.broadcast_to(cfg.p0_att, 3)
    sig[3:6] = cfg.p0_vel
    sig[9:12] = cfg.p0_gyro_bias
    sig[12:15] = cfg.p0_accel_bias
    if il >= 0:
        sig[il:il + 3] = cfg.p0_lever
    if ib >= 0:
        sig[ib:ib + 3] = np.broadcast_to(cfg.gnss_error_sigma, 3)
    p = np.diag(sig**2)
    p[6:9, 6:9] = tp @ np.diag(np.broadcast_to(cfg.p0_pos, 3) ** 2.0) @ tp.T
    return p


def _qc(cfg: FilterConfig, n: int, ib: int) -> np.ndarray:
    q = np.zeros(n)
    q[0:3], q[3:6] = cfg.gyro_arw**2, cfg.accel_vrw**2
    q[9:12], q[12:15] = cfg.gyro_bias_rw**2, cfg.accel_bias_rw**2
    if ib >= 0:  # stationary Gauss-Markov: PSD 2 sigma^2 / tau keeps the variance at sigma^2
        q[ib:ib + 3] = 2.0 * np.broadcast_to(np.asarray(cfg.gnss_error_sigma, float), 3) ** 2 / cfg.gnss_error_tau
    return q


def sample_index(t_imu: np.ndarray, t: np.ndarray, first: int = 0) -> np.ndarray:
    """Index of the IMU sample at each time of ``t`` (within half an IMU interval), -1 where none or before
    sample ``first``."""
    j = np.clip(np.searchsorted(t_imu, t), 1, t_imu.size - 1)
    j = np.where(np.abs(t_imu[j - 1] - t) < np.abs(t_imu[j] - t), j - 1, j)
    half = 0.5 * np.median(np.diff(t_imu))
    ok = (np.abs(t_imu[j] - t) <= half + 1e-9) & (j >= first)
    return np.where(ok, j, -1)


def _gnss_arrays(gnss: GnssFixes, t_imu, first: int):
    lla = ecef_to_lla(gnss.pos_ecef)
    k = sample_index(t_imu, gnss.t, first)
    good = (k >= 0) & np.isfinite(lla).all(1) & np.isfinite(gnss.vel_enu).all(1)
    good &= np.concatenate([[True], np.diff(k) > 0])
    idx = np.flatnonzero(good)
    z = np.concatenate([lla[idx], gnss.vel_enu[idx]], axis=1)
    r = np.zeros((idx.size, 6, 6))
    for j, i in enumerate(idx):
        tp = model.enu_to_geodetic(lla[i, 0], lla[i, 2])
        r[j, 0:3, 0:3] = tp @ gnss.pos_cov_enu[i] @ tp.T
        r[j, 3:6, 3:6] = gnss.vel_cov_enu[i]
    return idx, loop.Fixes(k[idx].astype(np.int64), z, r)


def _att_arrays(att: AttitudeFixes | None, t_imu, first: int):
    if att is None:
        return loop.Fixes(np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros((0, 3, 3)))
    k = sample_index(t_imu, att.t, first)
    good = (k >= 0) & np.isfinite(att.euler).all(1)
    good &= np.concatenate([[True], np.diff(k) > 0])
    return loop.Fixes(k[good].astype(np.int64), att.euler[good], att.cov[good])


def _spans(starts, lengths):
    """Indices starts[i] .. starts[i] + lengths[i] - 1 of every i, concatenated (int64)."""
    lengths = np.asarray(lengths, np.int64)
    first = np.cumsum(lengths) - lengths
    return (np.repeat(np.asarray(starts, np.int64) - first, lengths) + np.arange(lengths.sum())).astype(np.int64)


def _dd_arrays(dd: DDCarrier | None, t_imu, gate_p: float = 0.0, first: int = 1):
    """The loop's :class:`.loop.DDRows` (epochs at an IMU sample, one per sample, first kept)."""
    if dd is None:
        return loop.DDRows(np.zeros(0, np.int64), np.zeros(1, np.int64), np.zeros((0, 3)), np.zeros((0, 3)),
                           np.zeros(0), np.zeros(1, np.int64), np.zeros(0), np.zeros(0))
    k = sample_index(t_imu, dd.t, first)
    good = (k >= 0) & np.concatenate([[True], np.diff(k) > 0])
    idx = np.flatnonzero(good)
    m = np.diff(dd.offsets)
    rows = _spans(dd.offsets[idx], m[idx])
    crow = _spans(np.concatenate([[0], np.cumsum(m**2)])[idx], m[idx] ** 2)
    gate = chi2.isf(gate_p, m[idx]) if gate_p > 0 else np.full(idx.size, np.inf)
    return loop.DDRows(k[idx].astype(np.int64), np.concatenate([[0], np.cumsum(m[idx])]).astype(np.int64),
                       dd.los_enu[rows], dd.baseline_b[rows], dd.range_m[rows],
                       np.concatenate([[0], np.cumsum(m[idx] ** 2)]).astype(np.int64), dd.cov[crow],
                       np.asarray(gate, float))


class _LooselyCoupled:
    """Shared machinery; subclasses fix the state count and the update (Kalman or H-infinity)."""

    n_states = 15
    mode = 0
    name = "kf15"
    uses_dd = False

    def __init__(self, config: FilterConfig | None = None, init: InitialState | None = None):
        self.config = config or FilterConfig()
        self.init = init

    def run(self, imu: ImuData, gnss: GnssFixes, attitude: AttitudeFixes | None = None,
            init: InitialState | None = None, dd: DDCarrier | None = None) -> Solution:
        """Filter ``imu`` with ``gnss`` fixes (and ``attitude`` fixes, used by the 21-state filter, and the fixed
        DD carrier ``dd``, used by ``kf15_dd``). ``init`` (or the constructor's) is the navigation state at
        ``init.t``, an IMU sample time: earlier samples are not used."""
        init = init or self.init
        if init is None:
            raise EstimatorInputError(f"{self.name}.run: an InitialState is needed (see simkit.estimators.align)")
        k0 = int(np.searchsorted(imu.t, init.t - 1e-9))
        if k0 >= imu.t.size - 1:
            raise EstimatorInputError(f"{self.name}.run: init.t = {init.t} s is after the IMU data")
        if k0 > 0:  # start at the initial state's epoch (row k0 of increments covers the interval before it)
            imu = ImuData(imu.t[k0:], imu.gyro[k0:], imu.accel[k0:], imu.increments)
        comp = (from_increments if imu.increments else from_rates)(imu.t, imu.gyro, imu.accel)
        cfg = self.config
        n, il, ib = _layout(self.n_states, cfg)
        pos0 = np.asarray(init.pos_lla, float)
        nav0 = loop.Nav(Rotation.from_quat(init.quat_nb).as_matrix(), np.asarray(init.vel_enu, float), pos0,
                        np.asarray(cfg.gyro_bias0, float), np.asarray(cfg.accel_bias0, float), gnss.lever_arm_b.copy(),
                        np.zeros(3))
        first = 0 if cfg.update_at_start else 1  # sample 0 is the initial epoch
        idx, garr = _gnss_arrays(gnss, imu.t, first)
        aarr = _att_arrays(attitude if il >= 0 else None, imu.t, first)
        darr = _dd_arrays(dd if self.uses_dd else None, imu.t, float(cfg.dd_gate_p), first)
        out = loop.allocate(idx.size, n, aarr.k.size, darr.k.size)
        w_mean = window_mean_rate(comp, int(round(cfg.lever_rate_window_s / float(np.median(comp.dt)))))
        mode = self._mode()
        tuning = loop.Tuning(_p0(cfg, n, pos0[0], pos0[2], il, ib), _qc(cfg, n, ib), float(cfg.cov_dt), mode,
                             float(cfg.alpha), il, ib, float(cfg.gnss_error_tau))
        loop.run(loop.Samples(comp.phi, comp.dvb, comp.dt, comp.w_ib, w_mean), nav0, tuning, garr, aarr, darr, out,
                 None if mode == 0 else True)
        sol = self._solution(imu.t[garr.k], out, ib >= 0)
        return _with_dd(sol, garr.k, darr, out.dd_nis) if self.uses_dd else sol

    def _mode(self) -> int:
        if self.mode == 0:
            return 0
        if self.config.gamma_rule not in ("wu", "weighted"):
            raise EstimatorInputError(f"gamma_rule: expected 'wu' or 'weighted', got {self.config.gamma_rule!r}")
        return 1 if self.config.gamma_rule == "wu" else 2

    def _solution(self, t, out, gnss_error: bool) -> Solution:
        c, v, pos, cov, bias, lever, gamma, margin, nis, w, status, att_nis, _, gnss_err = out
        rot = Rotation.from_matrix(c)
        extras = {"gyro_bias": bias[:, :3], "accel_bias": bias[:, 3:], "lever_arm": lever, "nis": nis,
                  "nis_dof": np.where(np.isfinite(nis), w.shape[1], 0).astype(np.int32),
                  "innovation_std": w, "status": status}
        units = {"gyro_bias": "rad/s", "accel_bias": "m/s^2", "lever_arm": "m",
                 "nis": "1 (NIS of the position/velocity update at this epoch, chi-square with nis_dof dof)",
                 "nis_dof": "1 (rows of that update: 6; 0 where it was skipped)",
                 "innovation_std": "1",
                 "status": "0 ok, 1 gamma raised to the weighted rule (Wu's rule would violate the existence "
                           "condition or leave a margin below 1 - 1/alpha), 2 S not positive definite (update skipped)"}
        if gnss_error:
            extras["gnss_error"] = gnss_err
            units["gnss_error"] = "m (ENU: the estimated slowly varying error of the GNSS position fixes)"
        if self.mode == 1:
            extras.update(gamma=gamma, existence_margin=margin)
            units.update(gamma="1", existence_margin="1 (smallest eigenvalue of L^T (P^-1 - theta I + H^T R^-1 H) L, "
                                                    "P = L L^T)")
        config = {"estimator": self.name, **asdict(self.config)}
        if att_nis.size:
            config["attitude_nis_mean"] = float(np.nanmean(att_nis))
        return Solution(t=t, pos_ecef=lla_to_ecef(pos[:, 0], pos[:, 1], pos[:, 2]), vel_enu=v,
                        quat_nb=rot.as_quat(), euler=euler_from_attitude(rot), cov=cov,
                        state_names=STATE_NAMES[:self.n_states] + (GNSS_ERROR_STATES if gnss_error else ()),
                        extras=extras, extra_units=units, config=config)


class KalmanFilter15(_LooselyCoupled):
    """15-state loosely coupled error-state Kalman filter (Wu 2015 eqs 1-16), closed loop, lever arm known."""


class KalmanFilter21(_LooselyCoupled):
    """Badshah 2015's "21-state" filter: the 15 states plus the lever arm (body, m) as a state, and GNSS
    attitude fixes when given. The paper's own state list (attitude, velocity, position, gyro drift, accel bias,
    lever arm: 6 x 3) has 18 entries, so the solution carries 18 states; the name follows the paper."""

    n_states = 18
    name = "kf21"


class HInfinityFilter(_LooselyCoupled):
    """15-state H-infinity filter (Wu 2015 eq 17, Simon's form, theta = gamma^-2, adaptive gamma, alpha)."""

    mode = 1
    name = "hinf"


class KalmanFilter15DD(_LooselyCoupled):
    """``kf15_dd``: the 15-state Kalman filter plus the fixed DD carrier of each baseline as a measurement of the
    attitude error (tightly coupled attitude, Wang 2018 eq 16), ``run(imu, gnss, dd=DDCarrier(...))``."""

    name = "kf15_dd"
    uses_dd = True


def _with_dd(sol: Solution, g_k, darr, dd_nis) -> Solution:
    """Extras ``dd_rows`` (DD rows used at each output epoch's IMU sample, 0 where none) and ``dd_nis`` (NaN
    where none); config ``dd_epochs``, ``dd_rejected`` (by the gate), ``dd_nis_mean`` and ``dd_rows_mean``."""
    dk, m = darr.k, np.diff(darr.offsets)
    rows, nis = np.zeros(g_k.size, np.int32), np.full(g_k.size, np.nan)
    if dk.size:
        j = np.minimum(np.searchsorted(dk, g_k), dk.size - 1)
        hit = dk[j] == g_k
        jj = j[hit]
        rows[hit], nis[hit] = np.where(dd_nis[jj] <= darr.gate[jj], m[jj], 0), dd_nis[jj]
    extras = {**sol.extras, "dd_rows": rows, "dd_nis": nis}
    units = {**sol.extra_units,
             "dd_rows": "1 (fixed DD carrier rows in the update at this epoch; 0: none or gated out)",
             "dd_nis": "1 (NIS of the DD carrier update at this epoch, chi-square with dd_rows dof)"}
    config = {**sol.config, "dd_epochs": int(darr.k.size), "dd_rejected": int(np.sum(dd_nis > darr.gate)),
              "dd_nis_mean": float(np.nanmean(dd_nis)) if dd_nis.size else None,
              "dd_rows_mean": float(m.mean()) if m.size else 0.0}
    return Solution(**{**sol.__dict__, "extras": extras, "extra_units": units, "config": config})
