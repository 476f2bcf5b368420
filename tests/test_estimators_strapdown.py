"""Strapdown mechanisation against the analytic truth (an independent construction: the trajectory generator
forms w_ib^b and f_ib^b in closed form from the commanded motion) and the WGS-84 formulas of simkit.earth."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import simkit
from simkit import earth
from simkit.estimators import EstimatorInputError, strapdown
from simkit.estimators import nav
from simkit.frames import ecef_to_enu_vec

HD = ["--set", "scenario.duration_s=30", "--set", "trajectory.rate_hz=1000", "--set", "imu.preset=ideal",
      "--set", "gnss.rate_hz=1"]


def _overrides(extra=()):
    pairs = HD + list(extra)
    return [pairs[i + 1] for i in range(0, len(pairs), 2)]


@pytest.fixture(scope="module")
def hd_increments(tmp_path_factory):
    out = tmp_path_factory.mktemp("sd") / "hd.h5"
    return simkit.run("high_dynamic", out=out, overrides=_overrides(["--set", "imu.output=increments"]))


def _errors(ds, sol):
    lla = ds["truth/pos_lla"][:]
    dp = ecef_to_enu_vec(sol.pos_ecef - ds["truth/pos_ecef"][:], lla[:, 0], lla[:, 1])
    dv = sol.vel_enu - ds["truth/vel_enu"][:]
    da = (Rotation.from_quat(sol.quat_nb) * Rotation.from_quat(ds["truth/quat_nb"][:]).inv()).magnitude()
    return np.abs(dp).max(), np.abs(dv).max(), da.max()


def _init(ds):
    return dict(pos0_lla=ds["truth/pos_lla"][0], vel0_enu=ds["truth/vel_enu"][0], quat0_nb=ds["truth/quat_nb"][0])


def test_increments_reproduce_the_high_dynamic_truth(hd_increments):
    # 30 s of 5.5 g turns at 1 kHz from error-free increments: measured 4.4 um, 13 nm/s, 4.7 nrad
    with simkit.open(hd_increments) as ds:
        dp, dv, da = _errors(ds, strapdown(ds["imu/t"][:], dtheta=ds["imu/dtheta"][:], dvel=ds["imu/dvel"][:],
                                           **_init(ds)))
    assert dp < 1e-3 and dv < 1e-4 and da < 1e-7


def test_rates_reproduce_the_high_dynamic_truth(hd_increments):
    # the same motion from the sampled rates (quadratic-signal coning/sculling): measured 4.4 um, 13 nm/s, 4.7 nrad
    with simkit.open(hd_increments) as ds:
        dp, dv, da = _errors(ds, strapdown(ds["truth/t"][:], ds["truth/omega_ib_b"][:], ds["truth/f_ib_b"][:],
                                           **_init(ds)))
    assert dp < 2e-3 and dv < 1e-4 and da < 1e-5


def test_numba_earth_formulas_are_simkit_earth():
    lat = np.radians([-80.0, -33.0, 0.0, 34.2, 60.0, 89.0])
    h = np.array([-100.0, 0.0, 500.0, 4000.0, 12000.0, 30000.0])
    v = np.array([120.0, -80.0, 10.0])
    for la, hh in zip(lat, h):
        assert nav.gravity(la, hh) == pytest.approx(earth.normal_gravity(la, hh), rel=1e-15)
        assert np.allclose(nav.radii(la), earth.radii(la), rtol=1e-15)
        wie, wen = nav.rates(la, hh, v)
        assert np.allclose(wie, earth.earth_rate_enu(la), rtol=1e-15, atol=0)
        assert np.allclose(wen, earth.transport_rate_enu(la, hh, v), rtol=1e-14, atol=0)


def test_constant_rate_rotation_is_exact():
    # rotation at a constant rate about a fixed body axis, no Earth rate: C(t) = exp(w t) exactly (closed form)
    t = np.arange(201) * 0.01
    w = np.array([0.3, -1.2, 2.0])
    gyro = np.tile(w, (t.size, 1))
    c0 = Rotation.identity()
    sol = strapdown(t, gyro, np.zeros((t.size, 3)), pos0_lla=[0.0, 0.0, 1e7], vel0_enu=[0, 0, 0],
                    quat0_nb=c0.as_quat())
    # at the equator the n-frame turns at the Earth rate about north (plus a transport rate of the free fall,
    # 1e-10 rad over 2 s): C(t) = exp(-w_ie t) exp(w t)
    expect = Rotation.from_rotvec(-earth.earth_rate_enu(0.0) * t[-1]) * Rotation.from_rotvec(w * t[-1])
    err = (Rotation.from_quat(sol.quat_nb[-1]) * expect.inv()).magnitude()
    assert err < 1e-9


def test_bad_inputs_name_the_argument():
    t = np.arange(10) * 0.01
    with pytest.raises(EstimatorInputError, match="gyro: expected shape"):
        strapdown(t, np.zeros((9, 3)), np.zeros((10, 3)), pos0_lla=[0, 0, 0], vel0_enu=[0, 0, 0],
                  quat0_nb=[0, 0, 0, 1])
    with pytest.raises(EstimatorInputError, match="either gyro/accel"):
        strapdown(t, pos0_lla=[0, 0, 0], vel0_enu=[0, 0, 0], quat0_nb=[0, 0, 0, 1])
    with pytest.raises(EstimatorInputError, match="quat0_nb"):
        strapdown(t, np.zeros((10, 3)), np.zeros((10, 3)), pos0_lla=[0, 0, 0], vel0_enu=[0, 0, 0],
                  quat0_nb=[0, 0, 1])
