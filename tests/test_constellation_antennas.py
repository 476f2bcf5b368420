"""What each antenna sees (simkit.constellation.antenna_view) against the light-time solution computed at the
antenna itself (receiver_view, itself tested against the converged light-time equation), pymap3d's ecef2aer for
the angles, and central differences of both for the rates."""
import numpy as np
import pymap3d

from simkit import frames
from simkit.constellation import Sky, antenna_view, load, receiver_view

BRDM = "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"
WEEK = 2416


def _setup(n=40):
    const = load(BRDM, systems="G,C")
    sow = 86400.0 + 5000.0 + np.arange(n, dtype=float)
    vel = np.array([180.0, -120.0, 40.0])                         # uniform motion in ECEF, m/s
    rx = frames.lla_to_ecef(np.radians(34.2), np.radians(108.9), 3000.0) + np.arange(n)[:, None] * vel
    levers = np.array([[0.0, 0.0, 0.0], [4.0, -3.0, 1.0], [-2.5, 6.0, -0.5]])
    ant_pos = rx[:, None, :] + levers[None]
    ant_vel = np.broadcast_to(vel, ant_pos.shape).copy()
    return const, sow, ant_pos, ant_vel, Sky([const]).view(rx, np.full(n, WEEK), sow)


def _at_antenna(const, ant_pos, sow):
    return receiver_view(const, ant_pos, np.full(sow.size, WEEK), sow, velocity=True)


def test_range_clock_and_angles_equal_the_light_time_solution_at_each_antenna():
    const, sow, ant_pos, ant_vel, ref = _setup()
    view = antenna_view(ref, ant_pos, ant_vel)
    for a in range(ant_pos.shape[1]):
        geo = _at_antenna(const, ant_pos[:, a], sow)
        up = np.isfinite(geo.range) & (geo.elevation > 0.0)
        assert up.sum() > 400
        assert np.abs(view.range[:, a] - geo.range)[up].max() < 1e-6                   # m
        assert np.abs(view.sat_clock[:, a] - geo.sat_clock)[up].max() < 1e-17           # s
        lat, lon, h = pymap3d.ecef2geodetic(*ant_pos[:, a].T, deg=False)
        az, el, _ = pymap3d.ecef2aer(*np.moveaxis(geo.sat_pos, -1, 0), lat[:, None], lon[:, None], h[:, None],
                                     deg=False)
        assert np.abs(view.elevation[:, a] - el)[up].max() < 1e-9                       # rad
        daz = np.angle(np.exp(1j * (view.azimuth[:, a] - az)))
        assert np.abs(daz)[up].max() < 1e-9
        assert np.all((view.azimuth[:, a][up] >= 0.0) & (view.azimuth[:, a][up] < 2 * np.pi))
        assert np.abs(view.lla[:, a] - np.stack([lat, lon, h], -1)).max() < 1e-6


def test_range_rate_and_angle_rates_equal_central_differences():
    const, sow, ant_pos, ant_vel, ref = _setup()
    view = antenna_view(ref, ant_pos, ant_vel)
    h = 0.05
    for a in range(ant_pos.shape[1]):
        plus = _at_antenna(const, ant_pos[:, a] + h * ant_vel[:, a], sow + h)
        minus = _at_antenna(const, ant_pos[:, a] - h * ant_vel[:, a], sow - h)
        up = np.isfinite(plus.range) & np.isfinite(minus.range) & (plus.elevation > 0.1)
        rr = (plus.range - minus.range) / (2 * h)
        assert np.abs(view.range_rate[:, a] - rr)[up].max() < 2e-6                        # m/s
        angles = []
        for geo, t in ((plus, h), (minus, -h)):
            p = ant_pos[:, a] + t * ant_vel[:, a]
            lat, lon, hh = pymap3d.ecef2geodetic(*p.T, deg=False)
            angles.append(pymap3d.ecef2aer(*np.moveaxis(geo.sat_pos, -1, 0), lat[:, None], lon[:, None],
                                           hh[:, None], deg=False))
        el_rate = (angles[0][1] - angles[1][1]) / (2 * h)
        az_rate = np.angle(np.exp(1j * (angles[0][0] - angles[1][0]))) / (2 * h)
        assert np.abs(view.elevation_rate[:, a] - el_rate)[up].max() < 1e-9               # rad/s
        assert np.abs(view.azimuth_rate[:, a] - az_rate)[up].max() < 1e-9


def test_satellites_without_a_state_are_nan_at_every_antenna():
    const, sow, ant_pos, ant_vel, ref = _setup(5)
    ref = {k: v.copy() for k, v in ref.items()}
    ref["sat_pos"][2, 7] = np.nan
    view = antenna_view(ref, ant_pos, ant_vel)
    for x in (view.range, view.range_rate, view.elevation, view.azimuth, view.elevation_rate, view.azimuth_rate):
        assert np.isnan(x[2, :, 7]).all() and np.isfinite(x[[0, 1, 3, 4]][..., 7]).all()
