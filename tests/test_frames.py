"""Frames and time against independent authorities (scipy's generic Euler code, pymap3d, published values)."""
from datetime import datetime, timezone

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from simkit import earth, frames, gpstime


def test_closed_form_quaternion_matches_scipy_euler_sequence():
    a = np.random.default_rng(1).uniform(-3, 3, (1000, 3))
    q = frames.quat_from_euler(a[:, 0], a[:, 1], a[:, 2])
    r = Rotation.from_euler("ZXY", np.stack([-a[:, 2], a[:, 0], a[:, 1]], -1))
    assert (Rotation.from_quat(q).inv() * r).magnitude().max() < 1e-12
    e = frames.euler_from_attitude(frames.attitude_from_euler(0.1, -0.2, 5.0))
    assert np.allclose(e, [0.1, -0.2, 5.0])


def test_heading_is_clockwise_from_north_and_body_y_forward():
    rot = frames.attitude_from_euler(0.0, 0.0, np.radians(90.0))
    assert np.allclose(rot.apply([0, 1, 0]), [1, 0, 0])  # nose east at heading 90
    rot = frames.attitude_from_euler(0.0, np.radians(30.0), 0.0)
    assert rot.apply([1, 0, 0])[2] < 0  # positive roll: right wing down


def test_ned_frd_conversion_round_trip():
    rot = frames.attitude_from_euler(0.3, -0.4, 1.2)
    ned = frames.attitude_to_ned_frd(rot)
    # the FRD nose (x) must point where the RFU nose (y) points, expressed in NED
    assert np.allclose(ned.apply([1, 0, 0]), frames.enu_to_ned(rot.apply([0, 1, 0])))
    assert (frames.attitude_from_ned_frd(ned).inv() * rot).magnitude() < 1e-12


def test_normal_gravity_matches_tr8350_values():
    # TR8350.2 Table 3.4 / eq. 4-1: equator 9.7803253359, pole 9.8321849378 m/s^2
    assert earth.normal_gravity(0.0, 0.0) == pytest.approx(9.7803253359, abs=1e-10)
    assert earth.normal_gravity(np.pi / 2, 0.0) == pytest.approx(9.8321849378, abs=1e-9)
    # free-air gradient about -3.086e-6 s^-2 near the surface
    assert (earth.normal_gravity(0.8, 100.0) - earth.normal_gravity(0.8, 0.0)) / 100 == pytest.approx(-3.086e-6, rel=0.01)


def test_leap_table_is_skyfields_builtin_table():
    # read from skyfield's data file without importing skyfield: the same arrays as its timescale(builtin=True)
    from skyfield.api import load

    ts = load.timescale(builtin=True)
    dates, offsets = gpstime.leap_table()
    np.testing.assert_array_equal(dates, ts.leap_dates)
    np.testing.assert_array_equal(offsets, ts.leap_offsets)
    assert offsets[-1] == 37.0 and dates[-1] == 2457754.5  # TAI - UTC = 37 s from 2017-01-01 (IERS Bulletin C 52)


def test_gps_time_leap_seconds_and_bdt():
    assert gpstime.utc_to_gps(datetime(2016, 11, 8, tzinfo=timezone.utc)) == (1922, 172817.0)
    assert gpstime.utc_to_gps(datetime(1980, 1, 6, tzinfo=timezone.utc)) == (0, 0.0)
    assert gpstime.gps_to_utc(1922, 172817.0) == datetime(2016, 11, 8, tzinfo=timezone.utc)
    assert gpstime.bdt_to_gps(0, 0.0) == (1356, 14.0)
    w, s = gpstime.gps_to_bdt(2000, 5.0)
    assert (w, s) == (643, 604791.0)
