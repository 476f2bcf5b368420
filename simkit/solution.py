"""What an estimator returns and ``/solutions/<name>/`` stores: one frozen dataclass for any filter's output.

Conventions as the truth (README): positions ECEF (m) of the IMU centre, velocity relative to the Earth in ENU
(m/s), attitude body->ENU as a scalar-last quaternion and as Euler [pitch, roll, heading] (rad). Fields a
solution does not estimate are None (an attitude-only solution has no position).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Solution:
    """K solution epochs: ``t`` (K,) s since the scenario start; ``pos_ecef`` (K, 3) m; ``vel_enu`` (K, 3) m/s;
    ``quat_nb`` (K, 4); ``euler`` (K, 3) rad; ``cov`` (K, X, X) state covariance in SI units in the order of
    ``state_names`` (X,); ``extras`` name -> (K, ...) filter-specific outputs (biases, lever arm, gamma, fixed
    ambiguities, ratio, ...), each with its units in ``extra_units``; ``config`` the estimator configuration
    (JSON-ready)."""

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

    def __post_init__(self):
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
