"""The estimators' inputs: small frozen dataclasses of numpy arrays (SI units, frames in the names)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import EstimatorInputError


def _rows(name, x, n, width):
    x = np.asarray(x, dtype=float)
    if x.shape != (n, width):
        raise EstimatorInputError(f"{name}: expected shape ({n}, {width}), got {x.shape}")
    return x


def _cov(name, x, n, width):
    x = np.asarray(x, dtype=float)
    if x.shape == (width,):  # one set of standard deviations for every epoch
        x = np.broadcast_to(np.diag(x**2), (n, width, width))
    if x.shape != (n, width, width):
        raise EstimatorInputError(f"{name}: expected ({width},) sigmas or ({n}, {width}, {width}) covariances, "
                                  f"got shape {x.shape}")
    return np.ascontiguousarray(x)


@dataclass(frozen=True)
class ImuData:
    """IMU samples: ``t`` (N,) s; ``gyro`` (N, 3) rad/s and ``accel`` (N, 3) m/s^2 (w_ib^b, f_ib^b, body
    x right / y forward / z up) when ``increments`` is False, else ``gyro`` holds angle increments (rad) and
    ``accel`` velocity increments (m/s) over (t[k-1], t[k]]."""

    t: np.ndarray
    gyro: np.ndarray
    accel: np.ndarray
    increments: bool = False

    def __post_init__(self):
        t = np.asarray(self.t, dtype=float)
        if t.ndim != 1 or t.size < 2 or np.any(np.diff(t) <= 0):
            raise EstimatorInputError("imu.t: expected at least 2 strictly increasing times (s)")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "gyro", _rows("imu.gyro", self.gyro, t.size, 3))
        object.__setattr__(self, "accel", _rows("imu.accel", self.accel, t.size, 3))


@dataclass(frozen=True)
class GnssFixes:
    """Antenna position/velocity fixes: ``t`` (M,) s; ``pos_ecef`` (M, 3) m of the antenna phase centre;
    ``vel_enu`` (M, 3) m/s; ``pos_cov_enu`` and ``vel_cov_enu``: (3,) sigmas (m, m/s) or (M, 3, 3) covariances
    in ENU; ``lever_arm_b`` (3,) m, antenna from the IMU centre in body axes. Rows with NaN are skipped."""

    t: np.ndarray
    pos_ecef: np.ndarray
    vel_enu: np.ndarray
    pos_cov_enu: np.ndarray
    vel_cov_enu: np.ndarray
    lever_arm_b: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self):
        t = np.asarray(self.t, dtype=float)
        if t.ndim != 1:
            raise EstimatorInputError(f"gnss.t: expected shape (M,), got {t.shape}")
        m = t.size
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "pos_ecef", _rows("gnss.pos_ecef", self.pos_ecef, m, 3))
        object.__setattr__(self, "vel_enu", _rows("gnss.vel_enu", self.vel_enu, m, 3))
        object.__setattr__(self, "pos_cov_enu", _cov("gnss.pos_cov_enu", self.pos_cov_enu, m, 3))
        object.__setattr__(self, "vel_cov_enu", _cov("gnss.vel_cov_enu", self.vel_cov_enu, m, 3))
        lever = np.asarray(self.lever_arm_b, dtype=float)
        if lever.shape != (3,):
            raise EstimatorInputError(f"gnss.lever_arm_b: expected shape (3,), got {lever.shape}")
        object.__setattr__(self, "lever_arm_b", lever)


@dataclass(frozen=True)
class AttitudeFixes:
    """GNSS attitude: ``t`` (K,) s; ``euler`` (K, 3) [pitch, roll, heading] rad (body->ENU); ``cov`` (3,) sigmas
    (rad) or (K, 3, 3) covariances."""

    t: np.ndarray
    euler: np.ndarray
    cov: np.ndarray

    def __post_init__(self):
        t = np.asarray(self.t, dtype=float)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "euler", _rows("attitude.euler", self.euler, t.size, 3))
        object.__setattr__(self, "cov", _cov("attitude.cov", self.cov, t.size, 3))


@dataclass(frozen=True)
class InitialState:
    """Navigation state at ``t`` (s): ``pos_lla`` [lat rad, lon rad, h m] of the IMU centre, ``vel_enu`` (3,) m/s,
    ``quat_nb`` (4,) body->ENU scalar-last."""

    t: float
    pos_lla: np.ndarray
    vel_enu: np.ndarray
    quat_nb: np.ndarray


@dataclass(frozen=True)
class DDCarrier:
    """Fixed double-differenced carrier, K epochs, T rows: ``t`` (K,) s; ``offsets`` (K + 1,) int, the rows of
    epoch i are offsets[i]:offsets[i+1]; ``los_enu`` (T, 3) DD geometry G = -(e_s - e_ref) (ENU unit lines of
    sight receiver -> satellite); ``baseline_b`` (T, 3) m, the row's baseline (antenna k minus antenna 0) in the
    body frame; ``range_m`` (T,) m = lambda (DD phi - N_fixed) = G . C_b^n baseline_b + noise; ``cov`` (sum of
    m_i^2,) m^2, the m_i x m_i covariance of each epoch's rows, flattened row-major and concatenated."""

    t: np.ndarray
    offsets: np.ndarray
    los_enu: np.ndarray
    baseline_b: np.ndarray
    range_m: np.ndarray
    cov: np.ndarray

    def __post_init__(self):
        t = np.asarray(self.t, dtype=float)
        off = np.asarray(self.offsets, dtype=np.int64)
        if t.ndim != 1 or off.shape != (t.size + 1,) or off[0] != 0 or np.any(np.diff(off) < 1):
            raise EstimatorInputError(f"dd.offsets: expected {t.size + 1} increasing row offsets from 0 "
                                      f"(one or more rows per epoch), got shape {off.shape}")
        n = int(off[-1])
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "offsets", off)
        object.__setattr__(self, "los_enu", _rows("dd.los_enu", self.los_enu, n, 3))
        object.__setattr__(self, "baseline_b", _rows("dd.baseline_b", self.baseline_b, n, 3))
        object.__setattr__(self, "range_m", _rows("dd.range_m", np.reshape(self.range_m, (-1, 1)), n, 1)[:, 0])
        cov = np.ascontiguousarray(self.cov, dtype=float)
        if cov.shape != (int(np.sum(np.diff(off) ** 2)),):
            raise EstimatorInputError(f"dd.cov: expected {int(np.sum(np.diff(off) ** 2))} values (the m_i x m_i "
                                      f"blocks flattened), got shape {cov.shape}")
        object.__setattr__(self, "cov", cov)
