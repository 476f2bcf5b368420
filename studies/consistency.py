"""The filter's error state against truth, in the filter's own definitions (for NEES studies and tests; the
NEES and its chi-square bounds are the referee's: :func:`simkit.referee.stats.reduced_nees`, :func:`~simkit.referee.stats.mean_bounds`).

Error state (computed minus true, see :mod:`.model`): phi from C~ C^T = I - [phi x], dv = v~ - v,
dp = [L~ - L, lambda~ - lambda, h~ - h], and for the sensor states the residual error left after the filter's
compensation (true bias minus estimated bias), lever-arm estimate minus the true lever arm.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from simkit.frames import ecef_to_lla, wrap
from simkit.solution import Solution


def error_states(sol: Solution, quat_nb, vel_enu, pos_lla, gyro_bias=None, accel_bias=None, lever_arm=None,
                 gnss_error=None):
    """(K, X) error states of ``sol`` given the truth at its epochs: ``quat_nb`` (K, 4), ``vel_enu`` (K, 3),
    ``pos_lla`` (K, 3), and optionally the true sensor biases (K, 3) rad/s, m/s^2, lever arm (3,) m and error of
    the GNSS position fixes (K, 3) m ENU (NaN where the solution has those states and it is not given)."""
    names = list(sol.state_names)
    n = len(names)
    e = np.zeros((sol.t.size, n))
    d = Rotation.from_quat(sol.quat_nb) * Rotation.from_quat(quat_nb).inv()  # C~ C^T = exp(-[phi x])
    e[:, 0:3] = -d.as_rotvec()
    e[:, 3:6] = sol.vel_enu - vel_enu
    lla = ecef_to_lla(sol.pos_ecef)
    e[:, 6:9] = lla - pos_lla
    e[:, 7] = wrap(e[:, 7])
    if n >= 15:
        e[:, 9:12] = (gyro_bias if gyro_bias is not None else 0.0) - sol.extras["gyro_bias"]
        e[:, 12:15] = (accel_bias if accel_bias is not None else 0.0) - sol.extras["accel_bias"]
    if "lever_x" in names:
        e[:, 15:18] = sol.extras["lever_arm"] - (lever_arm if lever_arm is not None else 0.0)
    if "gnss_error_e" in names:
        i = names.index("gnss_error_e")
        e[:, i:i + 3] = sol.extras["gnss_error"] - gnss_error if gnss_error is not None else np.nan
    return e

