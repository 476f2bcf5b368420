"""Street canyons against their closed forms, over a day of real GPS + BDS satellites seen from a static antenna.

For a straight canyon of walls at lateral distances d1 (on the satellite's side, height H1) and d2 (the far side,
height H2) from the antenna, with k = tan(el) / |sin(az - axis)| the rise per metre across the street:
blocked direct path exactly when d1 k < H1; a reflection off the far wall's face exists when its point is below
the top (d2 k < H2) and the incoming ray clears the near wall ((2 d2 + d1) k >= H1); its extra path is the image
method's 2 d2 cos(el) |cos(az - wall normal)| = 2 d2 cos(el) |sin(az - axis)|. Both are checked to 1 mm: a state
may differ only where the ray passes a wall's top within 1 mm.
"""
import numpy as np
import pytest

import simkit
from simkit.io import open_dataset, read_gnss

ORIGIN = {"lat_deg": 34.2, "lon_deg": 108.9, "height_m": 400.0}


def day_scenario(canyon: dict, name="canyon_day", extra_env=None) -> dict:
    env = {"canyon": canyon, "reflection_range_m": 30000.0}
    env.update(extra_env or {})
    return {"scenario": {"name": name, "start": "2026-04-27T00:00:00Z", "duration_s": 86000.0},
            "trajectory": {"rate_hz": 0.01, "origin": ORIGIN,
                           "segment": [{"kind": "static", "duration_s": 86000.0}]},
            "gnss": {"rate_hz": 0.01, "elevation_mask_deg": 0.0, "signals": ["L1C", "B1I"],
                     "constellation": [{"source": "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"}],
                     "antenna": [{"lever_arm_m": [0.0, 0.0, 0.0]}]},
            "environment": env}


def los_of(path):
    with open_dataset(path) as ds:
        g = read_gnss(ds, truth=("los_state", "nlos_delay", "azimuth", "elevation"), satellites=False)
    t = g.truth
    return t["los_state"][:, 0], t["nlos_delay"][:, 0], t["azimuth"][:, 0], t["elevation"][:, 0]


def closed_form(az, el, axis_deg, d_left, d_right, h_left, h_right, half_length):
    """States and extra paths of the analytic canyon (antenna at the canyon's middle along the street)."""
    delta = az - np.radians(axis_deg)
    s = np.sin(delta)
    left_side = s < 0                                 # the satellite is to the left of the street axis
    d1, d2 = np.where(left_side, d_left, d_right), np.where(left_side, d_right, d_left)
    h1, h2 = np.where(left_side, h_left, h_right), np.where(left_side, h_right, h_left)
    with np.errstate(divide="ignore"):
        k = np.tan(el) / np.abs(s)
        cot = np.abs(np.cos(delta) / s)
    direct = ~((d1 * k < h1) & (d1 * cot <= half_length))
    refl = (d2 * k < h2) & ((2 * d2 + d1) * k >= h1) & (d2 * cot <= half_length)
    state = np.where(direct, np.where(refl, 1, 0), np.where(refl, 2, 3))
    extra = np.where(refl, 2 * d2 * np.cos(el) * np.abs(s), np.where(direct, 0.0, np.nan))
    # how close each ray passes a wall's top (m): a state may differ within 1 mm of a top
    margin = np.minimum.reduce([np.abs(d1 * k - h1), np.abs(d2 * k - h2), np.abs((2 * d2 + d1) * k - h1)])
    return state, extra, margin


def check(path, **geometry):
    state, delay, az, el = los_of(path)
    up = el > 0
    assert (state[~up & np.isfinite(el)] == 255).all()
    want, extra, margin = closed_form(az[up], el[up], **geometry)
    got = state[up]
    differ = got != want
    assert not (differ & (margin > 1e-3)).any(), np.flatnonzero(differ & (margin > 1e-3))[:10]
    same = ~differ
    np.testing.assert_allclose(delay[up][same], extra[same], atol=1e-3, equal_nan=True)
    return got


@pytest.mark.slow
def test_symmetric_canyon_blocks_and_reflects_as_the_closed_form(tmp_path):
    """Antenna in the middle of a 20 m x 60 m canyon: direct above atan(H / d(az)), NLOS between that and
    atan(H / 3 d(az)) off the far wall, blocked below; never both direct and reflected (the far wall's
    reflection point is then above its top)."""
    canyon = {"width_m": 20.0, "height_m": 60.0, "azimuth_deg": 30.0, "length_m": 40000.0}
    out = simkit.run(day_scenario(canyon), out=tmp_path / "sym.h5")
    got = check(out, axis_deg=30.0, d_left=10.0, d_right=10.0, h_left=60.0, h_right=60.0, half_length=20000.0)
    counts = np.bincount(got, minlength=4)
    assert counts[0] > 100 and counts[2] > 100 and counts[3] > 100 and counts[1] == 0


@pytest.mark.slow
def test_off_centre_asymmetric_canyon_has_direct_plus_reflected(tmp_path):
    """Antenna 4 m left of the axis of a 24 m canyon with a 25 m left and 70 m right wall (east-west street)."""
    axis = 90.0
    left = np.array([-np.cos(np.radians(axis)), np.sin(np.radians(axis))])
    canyon = {"width_m": 24.0, "left_height_m": 25.0, "right_height_m": 70.0, "azimuth_deg": axis,
              "length_m": 40000.0, "centre_en_m": (-4.0 * left).tolist()}
    out = simkit.run(day_scenario(canyon), out=tmp_path / "asym.h5")
    got = check(out, axis_deg=axis, d_left=8.0, d_right=16.0, h_left=25.0, h_right=70.0, half_length=20000.0)
    assert (np.bincount(got, minlength=4) > 20).all()


def test_one_geojson_building_reproduces_the_canyon_wall(tmp_path):
    """A 400 m x 20 m building, 60 m high, whose street face is the right wall of a one-sided canyon (written as
    longitude/latitude by pymap3d): the same state and extra path for every satellite over six hours."""
    import json

    import pymap3d

    axis = np.radians(30.0)
    along, left = np.array([np.sin(axis), np.cos(axis)]), np.array([-np.cos(axis), np.sin(axis)])
    corners = [a * 200.0 * along + lat * left for a, lat in ((-1, -10), (1, -10), (1, -30), (-1, -30), (-1, -10))]
    lat, lon, _ = pymap3d.enu2geodetic(np.array([c[0] for c in corners]), np.array([c[1] for c in corners]), 0.0,
                                       ORIGIN["lat_deg"], ORIGIN["lon_deg"], ORIGIN["height_m"])
    feature = {"type": "Feature", "properties": {"height": 60.0},
               "geometry": {"type": "Polygon", "coordinates": [np.stack([lon, lat], axis=1).tolist()]}}
    (tmp_path / "one.geojson").write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    short = {"scenario.duration_s": 21600.0, "trajectory.segment[0].duration_s": 21600.0}
    canyon = {"width_m": 20.0, "left_height_m": 0.0, "right_height_m": 60.0, "azimuth_deg": 30.0,
              "length_m": 400.0}
    a = los_of(simkit.run(day_scenario(canyon), out=tmp_path / "canyon.h5", overrides=short))
    building = day_scenario(canyon)
    building["environment"] = {"buildings": str(tmp_path / "one.geojson")}
    b = los_of(simkit.run(building, out=tmp_path / "building.h5", overrides=short))
    assert set(np.unique(a[0])) >= {0, 1, 3, 255}   # one wall: blocked, or direct with or without its reflection
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_allclose(a[1], b[1], atol=1e-3, equal_nan=True)


def test_body_mask_table_and_box_on_a_level_vehicle(tmp_path):
    """A level vehicle heading north (body x east, y north, z up): a mask table of 25 deg ahead (|body azimuth|
    < 90 deg) and 5 deg behind blocks exactly those elevations; a box 1 m north of the second antenna, 2 m above
    it and 200 m wide (a wall in the body frame) blocks exactly when tan(el) < 2 cos(az) (crossing its face,
    y = 1 m, below its top)."""
    sc = day_scenario({"width_m": 10.0, "height_m": 1.0})
    sc["gnss"]["antenna"] = [{"lever_arm_m": [0.0, 0.0, 0.0]}, {"lever_arm_m": [0.0, 0.0, 1.0]}]
    sc["environment"] = {"body_mask": [{"azimuth_deg": [0.0, 89.999, 90.0, 270.0, 270.001],
                                        "elevation_deg": [25.0, 25.0, 5.0, 5.0, 25.0], "antennas": [0]}],
                         "body_box": [{"min_m": [-100.0, 1.0, -100.0], "max_m": [100.0, 1.1, 3.0],
                                       "antennas": [1]}]}
    out = simkit.run(sc, out=tmp_path / "body.h5",
                     overrides={"scenario.duration_s": 21600.0, "trajectory.segment[0].duration_s": 21600.0})
    with open_dataset(out) as ds:
        g = read_gnss(ds, truth=("los_state", "azimuth", "elevation"), satellites=False)
    state, az, el = g.truth["los_state"], g.truth["azimuth"], g.truth["elevation"]
    up = el > 0
    ahead = np.cos(az) > 0
    mask = np.where(ahead, np.radians(25.0), np.radians(5.0))
    edge = np.abs(np.cos(az)) < 2e-5                  # the table's 0.001 deg ramps at +-90 deg
    want0 = np.where(el[:, 0] < mask[:, 0], 3, 0)
    ok0 = up[:, 0] & ~edge[:, 0] & (np.abs(el[:, 0] - mask[:, 0]) > 1e-9)
    np.testing.assert_array_equal(state[:, 0][ok0], want0[ok0])
    with np.errstate(divide="ignore"):
        rise = np.where(ahead[:, 1], np.tan(el[:, 1]) / np.cos(az[:, 1]), np.inf)   # per metre northwards
    want1 = np.where(rise < 2.0, 3, 0)
    ok1 = up[:, 1] & (np.abs(rise - 2.0) > 1e-6)
    np.testing.assert_array_equal(state[:, 1][ok1], want1[ok1])
    assert (want0[ok0] == 3).sum() > 50 and (want1[ok1] == 3).sum() > 50
