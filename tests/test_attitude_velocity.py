"""TDCP IMU-centre velocity (lever arm through the attitude) against the file's truth trajectory."""
import numpy as np
import pytest

import simkit
from simkit.attitude import SOLVERS, AttitudeInputError
from simkit.frames import ecef_to_enu_matrix

pytestmark = pytest.mark.slow  # simulates two files and solves the attitude (about 20 s)


def _truth_mean_velocity(ds, t_mid, dt=1.0):
    """IMU-centre displacement of /truth over each interval / dt, in ENU of the interval start (m/s)."""
    tt, pos = ds["truth/t"][:], ds["truth/pos_ecef"][:]
    k0, k1 = np.searchsorted(tt, t_mid - dt / 2 - 1e-9), np.searchsorted(tt, t_mid + dt / 2 - 1e-9)
    lla = ds["truth/pos_lla"][:][k0]
    return np.einsum("kij,kj->ki", ecef_to_enu_matrix(lla[:, 0], lla[:, 1]), pos[k1] - pos[k0]) / dt


@pytest.mark.parametrize("scenario, seconds, lever_rms_min", [("airborne_stim300", 300, 0.01),
                                                              ("xian_static_bds", 300, 0.0)])
def test_imu_centre_velocity_is_mm_per_s_against_the_truth(tmp_path, scenario, seconds, lever_rms_min):
    # the truth equals the receiver's models (gnss.truth_errors.model = "none"): the TDCP covariance takes carrier
    # noise only, not the rates of the realistic ionospheric residual (~3 mm/s RMS per range, docs/truth_errors.md)
    path = simkit.run(scenario, out=tmp_path / "f.h5", overrides=[f"scenario.duration_s={seconds}",
                                                                   "gnss.truth_errors.model='none'"])
    with simkit.open(path) as ds:
        truth = None
        for source, rate in (("attitude", "attitude"), ("truth", "attitude"), ("attitude", "imu")):
            sol = SOLVERS["tdcp"](ds, {"lever_attitude": source, "lever_rate": rate}, False)
            truth = _truth_mean_velocity(ds, sol.t) if truth is None else truth
            err = sol.extras["vel_enu_imu"] - truth
            ok = np.isfinite(err).all(1)
            assert ok.mean() > 0.95 and sol.config["lever_attitude_used"] == source
            rms = np.sqrt(np.mean(err[ok] ** 2, axis=0))
            assert np.all(rms < 0.005) and np.abs(err[ok]).max() < 0.03, (source, rate, rms)
            # the stated covariance is not optimistic (it takes 3 mm undifferenced carrier noise)
            sd = np.sqrt(np.diagonal(sol.extras["vel_enu_imu_cov"][ok], axis1=1, axis2=2))
            assert np.all(rms < 1.5 * np.sqrt(np.mean(sd ** 2, axis=0)))
        # the antenna velocity is not the IMU velocity where the body turns (the lever arm is metres)
        ant = np.sqrt(np.nanmean((sol.extras["vel_enu_antenna"] - truth) ** 2))
        assert ant > lever_rms_min
        with pytest.raises(AttitudeInputError, match="estimator.lever_rate"):
            SOLVERS["tdcp"](ds, {"lever_rate": "gps"}, False)
