"""Bad [environment] tables and malformed GeoJSON files: one clean error line naming the key, or the file and the
feature, exit 2, no output left behind."""
import json

import pytest

from simkit.environment.geojson import read_footprints
from simkit.errors import DataFileError
from tests.cli_errors import assert_clean_error

BASE = """
[scenario]
name = "env"
start = "2026-04-27T06:00:00Z"
duration_s = 2.0

[trajectory]
rate_hz = 1.0
origin = { lat_deg = 34.2, lon_deg = 108.9, height_m = 400.0 }

[[trajectory.segment]]
kind = "static"
duration_s = 2.0

[gnss]
[[gnss.constellation]]
source = "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"
[[gnss.antenna]]
lever_arm_m = [0.0, 0.0, 1.0]
"""

SQUARE = [[108.9, 34.2], [108.9001, 34.2], [108.9001, 34.2001], [108.9, 34.2001], [108.9, 34.2]]


def feature(geometry=None, **props):
    return {"type": "Feature", "properties": props or {"height": 20.0},
            "geometry": geometry or {"type": "Polygon", "coordinates": [SQUARE]}}


@pytest.mark.parametrize("env, expect", [
    ('canyon = { width_m = 20.0 }', "environment.canyon[0].height_m: missing required key"),
    ('canyon = { width_m = -1.0, height_m = 5.0 }', "environment.canyon[0].width_m: must be > 0"),
    ('canyon = { width_m = 20.0, height_m = 5.0, widht = 3 }', "environment.canyon[0].widht: unknown key"),
    ('buildings = "nosuch.geojson"', "environment.buildings: no such file 'nosuch.geojson'"),
    ('reflection_loss_db = 0.0', "environment.reflection_loss_db"),
    ('[[environment.body_mask]]\nazimuth_deg = [0.0, 90.0]\nelevation_deg = [10.0]',
     "environment.body_mask[0].elevation_deg: expected one elevation per azimuth (2), got 1"),
    ('[[environment.body_mask]]\nazimuth_deg = [90.0, 0.0]\nelevation_deg = [10.0, 5.0]',
     "environment.body_mask[0].azimuth_deg: expected increasing azimuths in [0, 360)"),
    ('[[environment.body_box]]\nmin_m = [-1.0, -1.0, 0.0]\nmax_m = [1.0, 1.0, 2.0]',
     "environment.body_box[0]: antenna 0 (lever arm [0.0, 0.0, 1.0]) is inside the box"),
    ('[[environment.body_box]]\nmin_m = [0.0, 0.0, 0.0]\nmax_m = [1.0, -1.0, 2.0]', "environment.body_box[0].max_m"),
    ('[[environment.body_mask]]\nazimuth_deg = [0.0]\nelevation_deg = [10.0]\nantennas = [3]',
     "environment.body_mask[0].antennas: antenna 3 does not exist"),
])
def test_bad_environment_tables_name_their_key(tmp_path, env, expect):
    (tmp_path / "s.toml").write_text(BASE + "\n[environment]\n" + env + "\n")
    assert_clean_error(["run", "s.toml", "-o", "out.h5"], tmp_path, expect=expect)


def test_environment_without_gnss_is_refused(tmp_path):
    text = BASE.split("[gnss]")[0] + "\n[environment]\ncanyon = { width_m = 20.0, height_m = 5.0 }\n"
    (tmp_path / "s.toml").write_text(text)
    assert_clean_error(["run", "s.toml", "-o", "out.h5"], tmp_path, expect="environment: needs a [gnss] section")


@pytest.mark.parametrize("doc, expect", [
    ("{not json", "not valid JSON"),
    ({"type": "Polygon", "coordinates": [SQUARE]}, "expected a GeoJSON FeatureCollection"),
    ({"type": "FeatureCollection", "features": []}, "no Polygon or MultiPolygon feature"),
    ({"type": "FeatureCollection", "features": [feature(), {"type": "Thing"}]}, "feature 1: expected an object"),
    ({"type": "FeatureCollection", "features": [feature({"type": "LineString", "coordinates": SQUARE})]},
     "feature 0: geometry 'LineString': expected a Polygon or MultiPolygon"),
    ({"type": "FeatureCollection", "features": [feature(levels=3)]}, "feature 0: property 'height' = None"),
    ({"type": "FeatureCollection", "features": [feature(height="tall", id="b7")]},
     "feature 0 (id b7): property 'height' = 'tall': expected a positive height"),
    ({"type": "FeatureCollection", "features": [feature({"type": "Polygon", "coordinates": [SQUARE[:-1]]})]},
     "feature 0: the outer ring is not closed"),
    ({"type": "FeatureCollection", "features": [feature({"type": "Polygon", "coordinates": [[[1, 2], [3, 4]]]})]},
     "feature 0: expected an outer ring of at least 4"),
    ({"type": "FeatureCollection", "features": [
        feature({"type": "Polygon", "coordinates": [[[200.0, 1.0], [1, 2], [2, 2], [200.0, 1.0]]]})]},
     "feature 0: coordinates outside longitude"),
])
def test_malformed_geojson_names_the_file_and_feature(tmp_path, doc, expect):
    path = tmp_path / "city.geojson"
    path.write_text(doc if isinstance(doc, str) else json.dumps(doc))
    with pytest.raises(DataFileError) as info:
        read_footprints(path)
    assert str(path) in str(info.value) and expect in str(info.value)
    (tmp_path / "s.toml").write_text(BASE + '\n[environment]\nbuildings = "city.geojson"\n')
    assert_clean_error(["run", "s.toml", "-o", "out.h5"], tmp_path, expect=expect)


def test_geojson_multipolygon_and_string_heights():
    """A MultiPolygon gives one footprint per polygon; "12 m" style heights (as in OpenStreetMap) are read."""
    import tempfile
    from pathlib import Path

    doc = {"type": "FeatureCollection", "features": [
        feature({"type": "MultiPolygon", "coordinates": [[SQUARE], [SQUARE]]}, height="12 m")]}
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "m.geojson"
        p.write_text(json.dumps(doc))
        feet = read_footprints(p)
    assert len(feet) == 2 and all(f.height_m == 12.0 for f in feet)


def test_a_route_of_canyons_and_buildings_beside_the_scenario(tmp_path):
    """[[environment.canyon]] tables give two walls each at the stated offsets; a relative GeoJSON path is taken
    from the scenario's folder, with height_offset_m added to its heights."""
    import numpy as np

    from simkit.scenario import load

    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "city.geojson").write_text(json.dumps({"type": "FeatureCollection",
                                                                "features": [feature(height=30.0)]}))
    text = BASE + """
[environment]
buildings = "city.geojson"
height_offset_m = -1.5
[[environment.canyon]]
width_m = 20.0
height_m = 40.0
azimuth_deg = 90.0
length_m = 100.0
[[environment.canyon]]
width_m = 16.0
left_height_m = 10.0
right_height_m = 0.0
centre_en_m = [100.0, 50.0]
"""
    (tmp_path / "sub" / "s.toml").write_text(text)
    env = load(tmp_path / "sub" / "s.toml").environment
    w = env.walls
    assert w.top.tolist() == [28.5] * 4 + [40.0, 40.0, 10.0]
    # the east-west canyon: walls 10 m north and south of the origin, from x = -50 to 50
    np.testing.assert_allclose(w.a[4:6], [[-50.0, 10.0], [-50.0, -10.0]], atol=1e-12)
    np.testing.assert_allclose(w.b[4:6], [[50.0, 10.0], [50.0, -10.0]], atol=1e-12)
    # the northward canyon at (100, 50): only its left (west) wall, 8 m west of the axis, 1000 m long
    np.testing.assert_allclose(w.a[6], [92.0, -450.0], atol=1e-12)
    np.testing.assert_allclose(w.b[6], [92.0, 550.0], atol=1e-12)
    assert env.n_canyons == 2 and env.buildings == "city.geojson"
