"""Filter consistency (Bar-Shalom's NEES/NIS tests): over a 50-run Monte Carlo with IMU and GNSS errors drawn
from exactly the filter's model, the run-averaged NEES and NIS stay within the 95 % chi^2 bounds."""
from dataclasses import replace

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


def _gauss_markov(t, sigma, tau, rng):
    """(K, 3) first-order Gauss-Markov samples at times ``t``: stationary, std ``sigma`` (3,), correlation time
    ``tau`` (the exact discrete form, independent of the filter's second-order discretisation)."""
    b = np.empty((t.size, 3))
    b[0] = rng.normal(size=3) * sigma
    for k in range(1, t.size):
        a = np.exp(-(t[k] - t[k - 1]) / tau)
        b[k] = a * b[k - 1] + np.sqrt(1.0 - a * a) * sigma * rng.normal(size=3)
    return b


def _one_run(tr, rng, cfg=CFG, drawn=None):
    """NEES (K,) over the 15 INS states (plus the GNSS-error states when ``cfg`` has them) and NIS of one run whose
    position fixes carry white noise and, when ``drawn`` = (sigma (3,), tau), a Gauss-Markov error."""
    t, n = tr["truth/t"], tr["truth/t"].size
    dt = t[1] - t[0]
    bg, ba = rng.normal(size=3) * CFG.p0_gyro_bias, rng.normal(size=3) * CFG.p0_accel_bias
    imu = ImuData(t, tr["imu/gyro"] + bg + rng.normal(size=(n, 3)) * CFG.gyro_arw / np.sqrt(dt),
                  tr["imu/accel"] + ba + rng.normal(size=(n, 3)) * CFG.accel_vrw / np.sqrt(dt))
    pos, vel_e = tr["gnss/truth/antenna_pos_ecef"][:, 0], tr["antenna_vel_ecef"][:, 0]
    lla = ecef_to_lla(pos)
    vel = ecef_to_enu_vec(vel_e, lla[:, 0], lla[:, 1])
    slow = np.zeros(pos.shape) if drawn is None else _gauss_markov(tr["gnss/t"], *drawn, rng)
    gnss = GnssFixes(tr["gnss/t"], pos + enu_to_ecef_vec(rng.normal(size=pos.shape) * POS_SIGMA + slow, lla[:, 0],
                                                          lla[:, 1]),
                     vel + rng.normal(size=vel.shape) * VEL_SIGMA, POS_SIGMA, np.full(3, VEL_SIGMA),
                     tr["gnss/antennas/lever_arm_b"][0])
    lla0 = tr["truth/pos_lla"][0]
    phi0 = rng.normal(size=3) * np.array(CFG.p0_att)
    q0 = (Rotation.from_rotvec(-phi0) * Rotation.from_quat(tr["truth/quat_nb"][0])).as_quat()
    dp0 = enu_to_geodetic(lla0[0], lla0[2]) @ (rng.normal(size=3) * np.array(CFG.p0_pos))
    init = InitialState(0.0, lla0 + dp0, tr["truth/vel_enu"][0] + rng.normal(size=3) * CFG.p0_vel, q0)
    sol = KalmanFilter15(cfg, init).run(imu, gnss)
    k = np.searchsorted(t, sol.t)
    e = error_states(sol, tr["truth/quat_nb"][k], tr["truth/vel_enu"][k], tr["truth/pos_lla"][k],
                     np.broadcast_to(bg, (k.size, 3)), np.broadcast_to(ba, (k.size, 3)),
                     gnss_error=slow[np.searchsorted(tr["gnss/t"], sol.t)])
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


def test_gnss_error_states_keep_a_filter_consistent_on_fixes_with_a_slowly_varying_error(truth):
    """Position fixes with a first-order Gauss-Markov error (sigma 1.5, 1.5, 3 m, tau 120 s) besides their white
    noise: the filter with the three GNSS-error states of that model stays within the chi^2 bounds over its 18
    states, while the 15-state filter, which takes the fixes as white, averages them down and fails the test by
    far (it reports a position covariance well below its error)."""
    drawn = (np.array([1.5, 1.5, 3.0]), 120.0)
    with_states = replace(CFG, gnss_error_sigma=tuple(drawn[0]), gnss_error_tau=drawn[1])
    rng = np.random.default_rng(21)
    runs = [_one_run(truth, rng, with_states, drawn) for _ in range(RUNS)]
    avg_nees = np.mean([r[0] for r in runs], axis=0)
    lo, hi = mean_bounds(18 * RUNS, RUNS)
    inside = np.mean((avg_nees > lo) & (avg_nees < hi))
    rng = np.random.default_rng(21)
    white = np.mean([_one_run(truth, rng, CFG, drawn)[0] for _ in range(RUNS)], axis=0)
    print(f"NEES with the states: mean {avg_nees.mean():.2f} (18 expected), {inside:.0%} of epochs in "
          f"[{lo:.2f}, {hi:.2f}]; without: mean {white.mean():.1f} (15 expected)")
    assert 0.9 * 18 < avg_nees.mean() < 1.1 * 18 and inside >= 0.9
    assert white.mean() > 3 * 15
