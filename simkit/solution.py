"""What an estimator returns and ``/solutions/<name>/`` stores: one frozen dataclass for any filter's output.

Conventions as the truth (README): positions ECEF (m), velocity relative to the Earth in ENU (m/s), both of the
solution's ``point``; attitude body->ENU as a scalar-last quaternion and as Euler [pitch, roll, heading] (rad).
Fields a solution does not estimate are None (an attitude-only solution has no position).

The point a solution estimates (group attribute ``point`` of ``/solutions/<name>``, default "imu" for files
written before it existed): "imu" (the IMU centre, where /truth is), "antenna:K" (the phase centre of antenna K,
lever arm /gnss/antennas/lever_arm_b[K]) or "lever_b:[x,y,z]" (a body-frame lever arm from the IMU centre, m).
"""
from __future__ import annotations

import json
import re
import sys
from dataclasses import dataclass, field

import numpy as np

POINT_FORMS = '"imu", "antenna:K" (K an antenna index) or "lever_b:[x,y,z]" (body frame, m)'
_ANTENNA = re.compile(r"^antenna:(\d+)$")


def parse_point(point: str) -> tuple[str, object]:
    """("imu", None), ("antenna", K) or ("lever_b", (3,) array in m, body frame) for a point string; ValueError
    naming the expected forms otherwise."""
    text = str(point).strip()
    if text == "imu":
        return "imu", None
    match = _ANTENNA.match(text)
    if match:
        return "antenna", int(match.group(1))
    if text.startswith("lever_b:"):
        try:
            lever = np.asarray(json.loads(text[len("lever_b:"):]), dtype=float)
        except (ValueError, TypeError):
            lever = np.empty(0)
        if lever.shape == (3,) and np.all(np.isfinite(lever)):
            return "lever_b", lever
    raise ValueError(f"point: expected {POINT_FORMS}, got {point!r}")


@dataclass(frozen=True)
class Solution:
    """K solution epochs: ``t`` (K,) s since the scenario start; ``pos_ecef`` (K, 3) m; ``vel_enu`` (K, 3) m/s;
    ``quat_nb`` (K, 4); ``euler`` (K, 3) rad; ``cov`` (K, X, X) state covariance in SI units in the order of
    ``state_names`` (X,); ``extras`` name -> (K, ...) filter-specific outputs (biases, lever arm, gamma, fixed
    ambiguities, ratio, ...), each with its units in ``extra_units``; ``config`` the estimator configuration
    (JSON-ready); ``point`` the point whose position and velocity are estimated (module docstring)."""

    t: np.ndarray
    pos_ecef: np.ndarray | None = None
    vel_enu: np.ndarray | None = None
    quat_nb: np.ndarray | None = None
    euler: np.ndarray | None = None
    cov: np.ndarray | None = None
    state_names: tuple[str, ...] = ()
    extras: dict[str, np.ndarray] = field(default_factory=dict)
    extra_units: dict[str, str] = field(default_factory=dict)
    config: dict = field(default_factory=dict)
    point: str = "imu"

    def __post_init__(self):
        parse_point(self.point)
        k = np.shape(self.t)[0] if np.ndim(self.t) == 1 else -1
        if k < 0:
            raise ValueError(f"Solution.t: expected shape (K,), got {np.shape(self.t)}")
        for name, width in (("pos_ecef", 3), ("vel_enu", 3), ("quat_nb", 4), ("euler", 3)):
            x = getattr(self, name)
            if x is not None and np.shape(x) != (k, width):
                raise ValueError(f"Solution.{name}: expected shape ({k}, {width}), got {np.shape(x)}")
        if self.cov is not None:
            n = len(self.state_names)
            if np.shape(self.cov) != (k, n, n):
                raise ValueError(f"Solution.cov: expected shape ({k}, {n}, {n}) for {n} state_names, "
                                 f"got {np.shape(self.cov)}")
        for name, x in self.extras.items():
            if np.shape(x)[:1] != (k,):
                raise ValueError(f"Solution.extras[{name!r}]: expected {k} rows, got shape {np.shape(x)}")


def warn_truth(name: str, keys: list, meaning: dict) -> None:
    """One stderr line naming the truth-derived inputs ``keys`` of estimator ``name`` (nothing when ``keys`` is
    empty); ``meaning`` {key: what it reads from /truth}."""
    if keys:
        what = "; ".join(f"estimator.{k}=truth ({meaning[k]})" for k in keys)
        print(f"warning: {name} reads /truth: {what}: a study input, not a receiver's", file=sys.stderr)
