"""Sources other than RINEX 3 broadcast: RINEX 4, almanacs (YUMA/SEM, derived), TLEs, nominal slots."""
import gzip

import numpy as np
import pytest

from simkit import frames
from simkit.constellation import almanac, load, nominal

from conftest import DATA as SHARED


def _common(a, b):
    ids = [s for s in a.sat_ids if s in b.sat_ids]
    return [a.sat_ids.index(s) for s in ids], [b.sat_ids.index(s) for s in ids]


def test_rinex4_records_and_bds_orbit_types_match_cnav1_sattype():
    """RINEX 4: every LNAV/D1/D2 record is read; our orbit-based GEO/IGSO/MEO decision equals the satellite
    type broadcast in the same file's BDS CNAV1 records (BO5 field 3: 1 GEO, 2 IGSO, 3 MEO)."""
    path = SHARED / "rinex_nav" / "BRD400DLR_S_20230710000_01D_MN.rnx.gz"
    lines = gzip.open(path, "rt").read().splitlines()
    heads = [ln.split() for ln in lines if ln.startswith("> EPH")]
    n_used = sum(h[2][0] in "GC" and h[3] in ("LNAV", "D1", "D2") for h in heads)
    const = load(path, systems="GC")
    assert len(const.records.sat) == n_used
    kepler_all = sum((h[2][0], h[3]) in {("G", "LNAV"), ("C", "D1"), ("C", "D2"), ("E", "INAV"), ("E", "FNAV"),
                                         ("J", "LNAV")} for h in heads)
    everything = load(path)
    assert len(everything.records.sat) == kepler_all > n_used
    assert len(everything.part("R").records.sat) == sum(h[2][0] == "R" and h[3] == "FDMA" for h in heads)
    sat_type = {}
    for i, ln in enumerate(lines):
        if ln.startswith("> EPH C") and ln.split()[3] == "CNV1":
            sat_type[ln.split()[2]] = {1: "GEO", 2: "IGSO", 3: "MEO"}[int(float(lines[i + 6][42:61]))]
    checked = [s for s in sat_type if s in const.sat_ids]
    assert len(checked) >= 20
    for s in checked:
        assert const.orbit_type[const.sat_ids.index(s)] == sat_type[s], s
    names = const.group_delay_names()
    assert {"TGD", "TGD1", "TGD2", "TGD_B1Cp", "TGD_B2ap"} <= set(names)
    delays = const.group_delays()
    print(f"RINEX 4: {n_used} LNAV/D1/D2 records, {len(checked)} BDS-3 types checked; C19 TGD_B1Cp "
          f"{delays['TGD_B1Cp'][const.sat_ids.index('C19')]:.3e} s")
    assert delays["TGD_B1Cp"][const.sat_ids.index("C19")] == pytest.approx(9.487848728895e-09)
    assert set(const.klobuchar) == {"G", "C"}


def test_space_padded_ids_and_gzip_give_the_same_constellation(tmp_path):
    src = SHARED / "rinex_nav" / "BRDC00WRD_U_20161580000_01D_MN.rnx"
    text = src.read_text()
    padded = "\n".join(f"{ln[0]} {int(ln[1:3])}{ln[3:]}" if ln[:1] in "GC" and ln[1] == "0" else ln
                       for ln in text.splitlines())
    assert "C 1 2016" in padded
    (tmp_path / "padded.gz").write_bytes(gzip.compress(padded.encode()))
    a, b = load(src), load(tmp_path / "padded.gz")
    assert a.sat_ids == b.sat_ids
    sow = 86400.0 + np.arange(0, 86400, 3600.0)
    np.testing.assert_array_equal(a.state(1900, sow)[0], b.state(1900, sow)[0])


def test_sem_and_yuma_of_the_same_almanac_agree():
    """Orekit's week-862 SEM and YUMA files carry the same almanac: semicircles and the 0.30 sc inclination
    offset (SEM) must give the positions of radians (YUMA) up to the files' rounding."""
    sem = load(SHARED / "sem" / "orekit_current_week0862.al3")
    yuma = load(SHARED / "yuma" / "orekit_yuma_week0862.txt")
    i, j = _common(sem, yuma)
    sow = 319488.0 + np.arange(-86400, 86400, 3600.0)
    d = np.linalg.norm(sem.state(1886, sow)[0][:, i] - yuma.state(1886, sow)[0][:, j], axis=-1)
    print(f"SEM vs YUMA (same almanac, +-1 day): max {np.nanmax(d):.3f} m over {len(i)} satellites")
    assert len(i) >= 30 and np.nanmax(d) < 1.0


def test_almanac_10bit_week_resolves_at_any_rollover_and_is_nan_outside_validity():
    alm = load(SHARED / "yuma" / "test_input_yuma377.txt")  # week 377: GPS week 1401 (2006) or 2425 (2026)
    p_2006, _ = alm.state(1401, 319488.0)
    p_2026, _ = alm.state(2425, 319488.0)
    np.testing.assert_array_equal(p_2006, p_2026)
    ok = np.isfinite(p_2006).all(axis=1)
    np.testing.assert_array_equal(ok, alm.records.healthy)  # unhealthy satellites give NaN
    assert ok.sum() >= 28
    assert np.isnan(alm.state(1401 + 2, 319488.0)[0]).all()  # 14 days > 7-day validity


def test_derived_almanac_vs_broadcast_ephemeris_over_a_day():
    """One record per satellite at noon, propagated over the whole day with the almanac model, against the
    broadcast ephemeris of the same day (GPS, BDS MEO, IGSO and GEO)."""
    eph = load("BRDM00DLR_S_20261170000_01D_MN.rnx.gz")
    alm = almanac.from_ephemeris(eph, 2416, 86400 + 43200.0)
    sow = 86400 + np.arange(0, 86400, 900.0)
    i, j = _common(eph, alm)
    d = np.linalg.norm(eph.state(2416, sow)[0][:, i] - alm.state(2416, sow)[0][:, j], axis=-1)
    types = np.char.add(eph.system[i], eph.orbit_type[i])
    for kind, limit_km in (("GMEO", 2.0), ("CMEO", 2.0), ("CIGSO", 4.0), ("CGEO", 4.0)):
        m = types == kind
        print(f"derived almanac vs ephemeris, 24 h, {kind}: median {np.nanmedian(d[:, m]) / 1e3:.2f} km, "
              f"max {np.nanmax(d[:, m]) / 1e3:.2f} km")
        assert np.nanmax(d[:, m]) < limit_km * 1e3


def test_tle_vs_yuma_same_fortnight():
    """CelesTrak TLEs (2022-02-03/04) and the YUMA almanac of 2022-02-17: both propagated to the midpoint."""
    yuma = load(SHARED / "yuma" / "almanac.yuma.week0149.405504.txt", validity_days=20)
    tle = load(SHARED / "tle" / "gps-ops_2022-02-04.txt", validity_days=20)
    i, j = _common(tle, yuma)
    out = {}
    for label, (week, sow) in {"TLE epoch": (2195, 5 * 86400.0), "YUMA toa": (2197, 405504.0)}.items():
        d = np.linalg.norm(tle.state(week, sow)[0][i] - yuma.state(week, sow)[0][j], axis=-1)
        out[label] = d
        print(f"TLE vs YUMA at {label}: median {np.nanmedian(d) / 1e3:.1f} km, max {np.nanmax(d) / 1e3:.1f} km "
              f"({np.isfinite(d).sum()} satellites)")
    assert np.nanmedian(out["YUMA toa"]) < 10e3 and np.nanmedian(out["TLE epoch"]) < 20e3


def test_bds_tle_classifies_geo_igso_meo_like_the_ephemeris():
    tle = load(SHARED / "tle" / "beidou_2022-02-04.txt")
    eph = load("BRDM00DLR_S_20261170000_01D_MN.rnx.gz")
    for s in ("C01", "C02", "C03", "C04", "C06", "C07", "C08", "C11", "C19", "C30"):
        assert tle.orbit_type[tle.sat_ids.index(s)] == eph.orbit_type[eph.sat_ids.index(s)], s


def test_nominal_gps_reproduces_the_published_slot_table():
    """At the table epoch the nominal orbits give back each slot's RAAN (from the GHA) and argument of latitude."""
    from simkit import gpstime

    c = load("nominal:gps")
    week, sow = gpstime.utc_to_gps(nominal.SPS_TABLE_EPOCH_UTC)
    pos, _, vel, _ = c.state(week, sow, velocity=True)
    # angular momentum of the osculating plane: inertial velocity without the J2 node regression
    rate = nominal._j2_node_rate(nominal.GPS_A, nominal.GPS_INC, 3.986005e14)
    v_plane = vel + np.cross([0, 0, 7.2921151467e-5 - rate], pos)
    h = np.cross(pos, v_plane)
    node_lon = np.arctan2(h[:, 0], -h[:, 1])
    raan = np.degrees(node_lon) + nominal.GPS_GHA_DEG
    node = np.stack([np.cos(node_lon), np.sin(node_lon), 0 * node_lon], -1)
    u = np.degrees(np.arctan2(np.einsum("ij,ij->i", np.cross(node, pos), h / np.linalg.norm(h, axis=1)[:, None]),
                              np.einsum("ij,ij->i", node, pos)))
    table = np.array(list(nominal.GPS_SLOTS.values()))
    np.testing.assert_allclose(np.mod(raan - table[:, 0] + 180, 360) - 180, 0, atol=1e-6)
    np.testing.assert_allclose(np.mod(u - table[:, 1] + 180, 360) - 180, 0, atol=1e-6)
    inc = np.degrees(np.arccos(h[:, 2] / np.linalg.norm(h, axis=1)))
    np.testing.assert_allclose(inc, 55.0, atol=1e-9)


def test_nominal_bds_geo_fixed_igso_crossing_and_walker():
    c = load("nominal:bds2")
    sow = np.arange(0, 86400.0 * 2, 600.0)
    lla = frames.ecef_to_lla(c.state(2416, sow)[0])
    lon = np.degrees(lla[..., 1])
    for prn, lon0 in {"C01": 140.0, "C02": 80.0, "C03": 110.5, "C04": 160.0, "C05": 58.75}.items():
        k = c.sat_ids.index(prn)
        np.testing.assert_allclose(lon[:, k], lon0, atol=1e-6)
        assert np.abs(lla[:, k, 0]).max() < 1e-9
    for prn, cross in {"C06": 118.0, "C09": 95.0}.items():
        k = c.sat_ids.index(prn)
        assert abs(0.5 * (lon[:, k].max() + lon[:, k].min()) - cross) < 0.01
        assert abs(np.degrees(lla[:, k, 0]).max() - 55.0) < 0.5
    b3 = load("nominal:bds3")
    meo = b3.orbit_type == "MEO"
    assert meo.sum() == 24 and (b3.orbit_type == "GEO").sum() == 3 and (b3.orbit_type == "IGSO").sum() == 3
    pos, _, vel, _ = b3.state(2416, 0.0, velocity=True)
    rate = nominal._j2_node_rate(nominal.BDS_MEO_A, nominal.BDS_INC, 3.986004418e14)
    h = np.cross(pos[meo], vel[meo] + np.cross([0, 0, 7.292115e-5 - rate], pos[meo]))
    normals = np.round(h / np.linalg.norm(h, axis=1)[:, None], 8)
    assert len(np.unique(normals, axis=0)) == 3  # three planes of 8
    np.testing.assert_allclose(np.degrees(np.arccos(h[:, 2] / np.linalg.norm(h, axis=1))), 55.0, atol=1e-9)
    r = np.linalg.norm(pos[meo], axis=1)
    np.testing.assert_allclose(r, 6378137.0 + 21528e3, rtol=1e-12)


def test_almanac_source_name_derives_from_the_middle_of_the_file():
    a = load("almanac:BRDC00WRD_U_20161580000_01D_MN.rnx.gz", validity_days=200)
    assert a.kind == "almanac" and "C01" in a.sat_ids and "G01" in a.sat_ids
    assert a.orbit_type[a.sat_ids.index("C01")] == "GEO"
    p, _ = a.state(1922, 180017.0)  # 2016-11-08 02:00 UTC, the Wang 2018 field test: 5 months out
    assert np.isfinite(p).all()
