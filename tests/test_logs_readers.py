"""Log readers (NMEA, GPX, KML/KMZ, CSV, /solutions) against published sentences and an independent parser
(pynmea2), and every bad log as one clear line from ``simkit run`` (exit 2, nothing written)."""
import zipfile
from datetime import date

import numpy as np
import pymap3d
import pynmea2
import pytest

from cli_errors import assert_clean_error
from log_writers import drive_truth, nmea_lines, noisy_log
from simkit import gpstime
from simkit.errors import DataFileError, ScenarioError
from simkit.logs import read
from simkit.scenario import load

# The GGA and RMC examples printed in most NMEA 0183 references (48 07.038 N, 11 31.000 E; 23 March 1994)
GGA = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47"
RMC = "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A"


def lla_deg(record):
    lat, lon, h = pymap3d.ecef2geodetic(*record.pos_ecef.T)
    return np.stack([lat, lon, h], -1)


def test_published_gga_and_rmc_sentences(tmp_path):
    p = tmp_path / "ref.nmea"
    p.write_text(RMC + "\n" + GGA + "\n")
    rec = read(p)
    lat, lon, h = lla_deg(rec)[0]
    assert lat == pytest.approx(48 + 7.038 / 60, abs=1e-9)
    assert lon == pytest.approx(11 + 31.0 / 60, abs=1e-9)
    assert h == pytest.approx(545.4 + 46.9, abs=1e-6)                 # above the geoid + geoid separation
    week, sow = gpstime.utc_to_gps(gpstime.parse_utc("1994-03-23T12:35:19Z"))
    assert (int(rec.week[0]), float(rec.sow[0])) == (week, pytest.approx(sow, abs=1e-9))
    speed = 22.4 * 1852 / 3600
    c = np.radians(84.4)
    assert rec.vel_enu[0, :2] == pytest.approx([speed * np.sin(c), speed * np.cos(c)], abs=1e-9)


def test_nmea_reader_agrees_with_pynmea2(tmp_path):
    tr = drive_truth(10.0, 60.0)
    t, lat, lon, h, _ = noisy_log(tr, 10, 2.0)
    lines = nmea_lines(t, lat, lon, h, vel_enu=tr["vel_enu"][::10])
    p = tmp_path / "drive.nmea"
    p.write_text("\n".join(lines) + "\n")
    rec = read(p)
    ref = [pynmea2.parse(ln) for ln in lines if "GGA" in ln]
    got = lla_deg(rec)
    assert len(ref) == len(got) == len(t)
    assert got[:, 0] == pytest.approx([m.latitude for m in ref], abs=1e-10)
    assert got[:, 1] == pytest.approx([m.longitude for m in ref], abs=1e-10)
    assert got[:, 2] == pytest.approx([float(m.altitude) + float(m.geo_sep) for m in ref], abs=1e-6)
    rmc = [pynmea2.parse(ln) for ln in lines if "RMC" in ln]
    speed = np.hypot(rec.vel_enu[:, 0], rec.vel_enu[:, 1])
    assert speed == pytest.approx([m.spd_over_grnd * 1852 / 3600 for m in rmc], abs=1e-9)
    dt = gpstime.diff_seconds(rec.week, rec.sow, rec.week[0], rec.sow[0])
    assert dt == pytest.approx(t - t[0], abs=1e-6)


def test_gga_only_log_takes_the_date_given_and_rolls_over_midnight(tmp_path):
    p = tmp_path / "night.nmea"
    body = ["GPGGA,235959.00,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,",
            "GPGGA,000000.00,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"]
    p.write_text("\n".join(f"${b}*{pynmea2.NMEASentence.checksum(b):02X}" for b in body) + "\n")
    rec = read(p, date_hint=date(2026, 4, 27))
    assert gpstime.diff_seconds(rec.week[1], rec.sow[1], rec.week[0], rec.sow[0]) == pytest.approx(1.0)
    week, sow = gpstime.utc_to_gps(gpstime.parse_utc("2026-04-27T23:59:59Z"))
    assert (int(rec.week[0]), float(rec.sow[0])) == (week, sow)


GPX = """<?xml version="1.0"?>
<gpx version="1.1" creator="test" xmlns="http://www.topografix.com/GPX/1/1"><trk><trkseg>
<trkpt lat="52.5" lon="13.4"><ele>80.5</ele><time>2026-04-27T06:00:00Z</time></trkpt>
<trkpt lat="52.5001" lon="13.4002"><ele>81.0</ele><time>2026-04-27T06:00:01.5Z</time></trkpt>
</trkseg></trk></gpx>"""


def test_gpx_track_points(tmp_path):
    p = tmp_path / "a.gpx"
    p.write_text(GPX)
    rec = read(p)
    assert lla_deg(rec) == pytest.approx(np.array([[52.5, 13.4, 80.5], [52.5001, 13.4002, 81.0]]), abs=1e-9)
    assert gpstime.diff_seconds(rec.week[1], rec.sow[1], rec.week[0], rec.sow[0]) == pytest.approx(1.5)


KML = """<?xml version="1.0"?><kml xmlns="http://www.opengis.net/kml/2.2" xmlns:gx="http://www.google.com/kml/ext/2.2">
<Document><Placemark><gx:Track><when>2026-04-27T06:00:00Z</when><when>2026-04-27T06:00:02Z</when>
<gx:coord>13.4 52.5 80</gx:coord><gx:coord>13.4003 52.5001 82</gx:coord></gx:Track></Placemark></Document></kml>"""
PLACEMARKS = """<?xml version="1.0"?><kml xmlns="http://www.opengis.net/kml/2.2"><Document>
<Placemark><TimeStamp><when>2026-04-27T06:00:00Z</when></TimeStamp><Point><coordinates>13.4,52.5,80</coordinates></Point></Placemark>
<Placemark><TimeStamp><when>2026-04-27T06:00:02Z</when></TimeStamp><Point><coordinates>13.4003,52.5001,82</coordinates></Point></Placemark>
</Document></kml>"""


@pytest.mark.parametrize("text", [KML, PLACEMARKS])
@pytest.mark.parametrize("zipped", [False, True])
def test_kml_tracks_and_timestamped_placemarks(tmp_path, text, zipped):
    if zipped:
        p = tmp_path / "a.kmz"
        with zipfile.ZipFile(p, "w") as z:
            z.writestr("doc.kml", text)
    else:
        p = tmp_path / "a.kml"
        p.write_text(text)
    rec = read(p)
    assert lla_deg(rec) == pytest.approx(np.array([[52.5, 13.4, 80.0], [52.5001, 13.4003, 82.0]]), abs=1e-9)
    assert gpstime.diff_seconds(rec.week[1], rec.sow[1], rec.week[0], rec.sow[0]) == pytest.approx(2.0)


def test_csv_time_and_position_forms_agree(tmp_path):
    lat, lon, h = 52.5, 13.4, 80.0
    x, y, z = pymap3d.geodetic2ecef(lat, lon, h)
    week, sow = gpstime.utc_to_gps(gpstime.parse_utc("2026-04-27T06:00:00Z"))
    unix = gpstime.parse_utc("2026-04-27T06:00:00Z").timestamp()
    files = {
        "a.csv": f"gps_week,gps_sow,lat_deg,lon_deg,h_m\n{week},{sow},{lat},{lon},{h}\n{week},{sow + 1},{lat},{lon},{h}\n",
        "b.csv": f"# comment\nunix_s,x_ecef_m,y_ecef_m,z_ecef_m,vel_n_m_per_s,vel_e_m_per_s,vel_d_m_per_s\n"
                 f"{unix},{x:.17g},{y:.17g},{z:.17g},1,2,3\n{unix + 1},{x:.17g},{y:.17g},{z:.17g},1,2,3\n",
        "c.csv": f"utc,lat_rad,lon_rad,h_m\n2026-04-27T06:00:00Z,{np.radians(lat):.17g},{np.radians(lon):.17g},{h}\n"
                 f"2026-04-27T06:00:01Z,{np.radians(lat):.17g},{np.radians(lon):.17g},{h}\n",
    }
    recs = []
    for name, text in files.items():
        (tmp_path / name).write_text(text)
        recs.append(read(tmp_path / name))
    for r in recs:
        assert (int(r.week[0]), float(r.sow[0])) == (week, pytest.approx(sow, abs=1e-9))
        assert r.pos_ecef[0] == pytest.approx([x, y, z], abs=1e-6)
    assert recs[1].vel_enu[0] == pytest.approx([2.0, 1.0, -3.0])


def test_solutions_group_as_a_log(tmp_path):
    from simkit import run
    from simkit.io import write_solution
    from simkit.io.readers import read_truth
    from simkit.io import open_dataset
    from simkit.solution import Solution

    h5 = run({"scenario": {"name": "s", "start": "2026-04-27T06:00:00Z", "duration_s": 20.0},
              "trajectory": {"rate_hz": 10.0, "origin": {"lat_deg": 52.5, "lon_deg": 13.4},
                             "initial": {"speed_m_per_s": 10.0}}}, out=tmp_path / "s.h5")
    with open_dataset(h5) as ds:
        tr = read_truth(ds)
    write_solution(h5, "fix", Solution(t=tr.t[::10], pos_ecef=tr.pos_ecef[::10], vel_enu=tr.vel_enu[::10]))
    rec = read(h5)
    week, sow = gpstime.utc_to_gps(gpstime.parse_utc("2026-04-27T06:00:00Z"))
    track = rec.track(week, sow, 0.0, 20.0)
    assert track.t == pytest.approx(tr.t[::10], abs=1e-9)
    assert track.pos_ecef == pytest.approx(tr.pos_ecef[::10], abs=1e-6)


# ---- bad logs: one line each, from the command line ----

def _good_nmea(n=20, step_m=10.0, dt=1.0):
    lat0, lon0 = 52.5, 13.4
    t = np.arange(n) * dt
    lat, lon, h = pymap3d.enu2geodetic(np.zeros(n), t * step_m / dt, np.zeros(n), lat0, lon0, 80.0)
    return t, lat, lon, h


def _scenario(tmp_path, log_name, extra=""):
    (tmp_path / "s.toml").write_text(
        f'[scenario]\nname = "s"\nstart = "2026-04-27T06:00:01Z"\nduration_s = 10.0\n\n'
        f'[trajectory]\nrate_hz = 10.0\nsource = "{log_name}"\n{extra}')
    return "s.toml"


def _nmea(t, lat, lon, h):
    return "\n".join(nmea_lines(t, lat, lon, h, rmc=False)) + "\n"


def _bad_cases():
    t, lat, lon, h = _good_nmea()
    good = _nmea(t, lat, lon, h)
    lines = good.splitlines()
    cases = {
        "checksum": ("a.nmea", "\n".join(lines[:3] + [lines[3][:-2] + "00"] + lines[4:]), "a.nmea:4: bad checksum"),
        "not nmea": ("a.nmea", good + "hello\n", "expected an NMEA sentence"),
        "no geoid": ("a.nmea", "$" + (b := "GPGGA,060000,5230.000,N,01324.000,E,1,08,0.9,80.0,M,,M,,") +
                     f"*{pynmea2.NMEASentence.checksum(b):02X}\n", "ellipsoidal height is unknown"),
        "backwards": ("a.nmea", _nmea(np.r_[t[:5], t[3], t[6:]], lat, lon, h), "time does not increase"),
        "jump": ("a.nmea", _nmea(t, np.r_[lat[:6], lat[6] + 0.01, lat[7:]], lon, h), "jump of"),
        "few": ("a.nmea", _nmea(t[:3] * 6, lat[:3], lon[:3], h[:3]), "need at least 4"),
        "gap": ("a.nmea", _nmea(np.r_[t[:4], t[4:] + 11.0], lat, lon, h), "longer than trajectory.max_gap_s"),
        "short": ("a.nmea", _nmea(t[:8], lat[:8], lon[:8], h[:8]), "does not cover scenario.start"),
        "standing": ("a.nmea", _nmea(t, np.full_like(lat, lat[0]), lon, h), "never moves at"),
        "gpx time": ("a.gpx", GPX.replace("<time>2026-04-27T06:00:00Z</time>", ""), "track point 1"),
        "gpx xml": ("a.gpx", GPX[:-30], "not well-formed XML"),
        "kml line": ("a.kml", '<kml xmlns="http://www.opengis.net/kml/2.2"><Placemark><LineString><coordinates>'
                     '13.4,52.5,0 13.5,52.6,0</coordinates></LineString></Placemark></kml>', "a LineString has no times"),
        "kmz": ("a.kmz", "not a zip", "not a zip archive"),
        "csv column": ("a.csv", "gps_week,gps_sow,lat_deg,lon_deg\n2416,0,52,13\n", "position: expected"),
        "csv number": ("a.csv", "gps_week,gps_sow,lat_deg,lon_deg,h_m\n2416,0,52,13,x\n", "a.csv:2: column h_m"),
        "csv time": ("a.csv", "lat_deg,lon_deg,h_m\n52,13,0\n52,13,0\n", "time: expected"),
        "suffix": ("a.txt", good, "unknown log format"),
    }
    return cases


@pytest.mark.parametrize("case", list(_bad_cases()))
def test_bad_log_is_one_line(tmp_path, case):
    name, text, expect = _bad_cases()[case]
    (tmp_path / name).write_text(text)
    line = assert_clean_error(["run", _scenario(tmp_path, name), "-o", "out.h5"], tmp_path, expect)
    assert name in line or case == "suffix"


@pytest.mark.parametrize("extra, expect", [
    ('origin = { lat_deg = 1.0, lon_deg = 2.0 }\n', "trajectory.origin: cannot be given with trajectory.source"),
    ('attitude = "log"\n', "has no attitude"),
    ('position_sigma_m = [1.0, 2.0]\n', "trajectory.position_sigma_m"),
    ('attitude = "banked"\n', "trajectory.attitude: must be one of"),
    ('outliers = "ignore"\n', "trajectory.outliers: must be one of"),
])
def test_bad_keys_beside_source(tmp_path, extra, expect):
    t, lat, lon, h = _good_nmea()
    (tmp_path / "a.nmea").write_text(_nmea(t, lat, lon, h))
    assert_clean_error(["run", _scenario(tmp_path, "a.nmea", extra), "-o", "out.h5"], tmp_path, expect)


def test_missing_log_names_the_key(tmp_path):
    assert_clean_error(["run", _scenario(tmp_path, "nowhere.nmea"), "-o", "out.h5"], tmp_path,
                       "trajectory.source: no such log file")


def test_good_log_relative_to_the_scenario_runs(tmp_path):
    t, lat, lon, h = _good_nmea()
    sub = tmp_path / "sub"
    sub.mkdir()
    (sub / "a.nmea").write_text(_nmea(t, lat, lon, h))
    sc = load(sub / _scenario(sub, "a.nmea", "position_sigma_m = 0.5\n"))
    assert sc.trajectory.path is not None
    assert np.degrees(sc.trajectory.lat_rad) == pytest.approx(lat[1], abs=1e-5)   # starts 1 s into the log
    with pytest.raises((DataFileError, ScenarioError)):
        load({"scenario": {"name": "s", "start": "2026-04-27T06:00:01Z", "duration_s": 10.0},
              "trajectory": {"rate_hz": 10.0, "source": "a.nmea"}})   # a dict has no folder: cwd


def test_a_run_from_a_log_records_the_log_and_the_fit(tmp_path):
    import hashlib
    import json

    from simkit import run
    from simkit.io import open_dataset

    t, lat, lon, h = _good_nmea()
    (tmp_path / "a.nmea").write_text(_nmea(t, lat, lon, h))
    out = run(tmp_path / _scenario(tmp_path, "a.nmea", "position_sigma_m = 0.5\n"), out=tmp_path / "a.h5")
    with open_dataset(out) as ds:
        log = json.loads(ds.group_attrs("truth")["log"])
        n = len(ds["truth/t"][:])
    assert log["sha256"] == hashlib.sha256((tmp_path / "a.nmea").read_bytes()).hexdigest()
    assert log["source"] == "a.nmea" and log["sigma_source"] == "stated" and log["attitude"] == "ground"
    assert n == 101
    again = run(tmp_path / "s.toml", out=tmp_path / "b.h5")            # the fit is deterministic
    with open_dataset(out) as a, open_dataset(again) as b:
        for key in ("truth/pos_ecef", "truth/quat_nb", "truth/omega_ib_b", "truth/f_ib_b"):
            assert np.array_equal(a[key][:], b[key][:])


def test_a_long_gap_in_the_margin_outside_the_run_is_not_an_error(tmp_path):
    """Samples up to 30 s outside the run steady its ends; a long gap among them is cut off, not refused."""
    t, lat, lon, h = _good_nmea(n=40)
    keep = (t < 3) | (t > 16)             # a 14 s gap from 2 s to 17 s, then the run from 18 s
    (tmp_path / "a.nmea").write_text(_nmea(t[keep], lat[keep], lon[keep], h[keep]))
    text = (tmp_path / _scenario(tmp_path, "a.nmea", "position_sigma_m = 0.5\n")).read_text()
    (tmp_path / "s.toml").write_text(text.replace("06:00:01Z", "06:00:18Z"))
    sc = load(tmp_path / "s.toml")
    assert sc.trajectory.path.summary()["samples_used"] == 23     # 17..39 s: the samples before the gap are dropped
