"""Filter consistency (Bar-Shalom's NEES/NIS tests): over a 50-run Monte Carlo with IMU and GNSS errors drawn
from exactly the filter's model, the run-averaged NEES and NIS stay within the 95 % chi^2 bounds."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import simkit
from simkit.estimators import FilterConfig, GnssFixes, ImuData, InitialState, KalmanFilter15
from simkit.estimators.model import enu_to_geodetic
from simkit.frames import ecef_to_enu_vec, ecef_to_lla, enu_to_ecef_vec
from simkit.referee.stats import mean_bounds, reduced_nees
from studies.consistency import error_states

RUNS = 50
CFG = FilterConfig(gyro_arw=2.9e-5, accel_vrw=8.3e-4, p0_att=(0.005, 0.005, 0.02), p0_vel=0.1,
                   p0_pos=(2.0, 2.0, 3.0), p0_gyro_bias=4.8e-5, p0_accel_bias=9.8e-3)
POS_SIGMA, VEL_SIGMA = np.array([1.0, 1.0, 2.0]), 0.05


@pytest.fixture(scope="module")
def truth(tmp_path_factory):
    out = tmp_path_factory.mktemp("mc") / "q.h5"
    simkit.run("quickstart", out=out, overrides=["imu.preset=ideal", "gnss.rate_hz=2.0"])
    with simkit.open(out) as ds:
        return {k: ds[k][:] for k in ("truth/t", "truth/pos_lla", "truth/vel_enu", "truth/quat_nb", "imu/gyro",
                                      "imu/accel", "gnss/t", "gnss/truth/antenna_pos_ecef",
                                      "gnss/antennas/lever_arm_b")} | {"antenna_vel_ecef": ds[
            "gnss/truth/antenna_vel_ecef"][:]}


def _one_run(tr, rng):
    t, n = tr["truth/t"], tr["truth/t"].size
    dt = t[1] - t[0]
    bg, ba = rng.normal(size=3) * CFG.p0_gyro_bias, rng.normal(size=3) * CFG.p0_accel_bias
    imu = ImuData(t, tr["imu/gyro"] + bg + rng.normal(size=(n, 3)) * CFG.gyro_arw / np.sqrt(dt),
                  tr["imu/accel"] + ba + rng.normal(size=(n, 3)) * CFG.accel_vrw / np.sqrt(dt))
    pos, vel_e = tr["gnss/truth/antenna_pos_ecef"][:, 0], tr["antenna_vel_ecef"][:, 0]
    lla = ecef_to_lla(pos)
    vel = ecef_to_enu_vec(vel_e, lla[:, 0], lla[:, 1])
    gnss = GnssFixes(tr["gnss/t"], pos + enu_to_ecef_vec(rng.normal(size=pos.shape) * POS_SIGMA, lla[:, 0],
                                                          lla[:, 1]),
                     vel + rng.normal(size=vel.shape) * VEL_SIGMA, POS_SIGMA, np.full(3, VEL_SIGMA),
                     tr["gnss/antennas/lever_arm_b"][0])
    lla0 = tr["truth/pos_lla"][0]
    phi0 = rng.normal(size=3) * np.array(CFG.p0_att)
    q0 = (Rotation.from_rotvec(-phi0) * Rotation.from_quat(tr["truth/quat_nb"][0])).as_quat()
    dp0 = enu_to_geodetic(lla0[0], lla0[2]) @ (rng.normal(size=3) * np.array(CFG.p0_pos))
    init = InitialState(0.0, lla0 + dp0, tr["truth/vel_enu"][0] + rng.normal(size=3) * CFG.p0_vel, q0)
    sol = KalmanFilter15(CFG, init).run(imu, gnss)
    k = np.searchsorted(t, sol.t)
    e = error_states(sol, tr["truth/quat_nb"][k], tr["truth/vel_enu"][k], tr["truth/pos_lla"][k],
                     np.broadcast_to(bg, (k.size, 3)), np.broadcast_to(ba, (k.size, 3)))
    return reduced_nees(e, sol.cov)[0], sol.extras["nis"]


def test_nees_and_nis_of_a_matched_filter_are_within_the_chi2_bounds(truth):
    rng = np.random.default_rng(2015)
    runs = [_one_run(truth, rng) for _ in range(RUNS)]
    avg_nees = np.mean([r[0] for r in runs], axis=0)
    avg_nis = np.mean([r[1] for r in runs], axis=0)
    lo, hi = mean_bounds(15 * RUNS, RUNS)
    inside = np.mean((avg_nees > lo) & (avg_nees < hi))
    lo6, hi6 = mean_bounds(6 * RUNS, RUNS)
    inside_nis = np.mean((avg_nis > lo6) & (avg_nis < hi6))
    print(f"NEES: mean {avg_nees.mean():.2f} (15 expected), {inside:.0%} of epochs in [{lo:.2f}, {hi:.2f}]; "
          f"NIS: mean {avg_nis.mean():.2f} (6), {inside_nis:.0%} in [{lo6:.2f}, {hi6:.2f}]")
    assert 0.9 * 15 < avg_nees.mean() < 1.1 * 15
    assert inside >= 0.9 and inside_nis >= 0.9
