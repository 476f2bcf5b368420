"""Galileo TLE sets: CelesTrak names to E-ids (simkit.constellation.galileo_satellites) and SGP4 states.

The TLE file is CelesTrak's Galileo set of 2020-04-19..23 (tests/data/tle/galileo_2020-04-23.txt). No broadcast
ephemeris of that week is stored, so SGP4 positions are not compared with broadcast orbits at a common epoch
(see docs/systems.md). The GSAT -> SVID table is checked against the broadcast ephemerides of 2026 (BRDM file)
by what does not change over the years: which satellites are the two in eccentric orbits (GSAT0201/0202, launched
into a wrong orbit in 2014) and which satellites share an orbital plane.
"""
import subprocess
import sys

import numpy as np
import pytest

from conftest import DATA
from simkit.constellation import galileo_satellites, kepler, load

TLE = DATA / "tle" / "galileo_2020-04-23.txt"
NAV = DATA / "rinex_nav" / "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"
OMEGA_E = 7.2921151467e-5


def _tle_elements():
    """{name: (raan deg, eccentricity)} from line 2 of each TLE (columns 18-25 and 27-33)."""
    lines = [ln.rstrip() for ln in TLE.read_text().splitlines() if ln.strip()]
    return {lines[k].strip(): (float(lines[k + 2][17:25]), float("0." + lines[k + 2][26:33]))
            for k in range(0, len(lines), 3)}


def test_names_map_to_svids_by_label_and_by_table():
    elements = _tle_elements()
    assert len(elements) == 26
    for name in elements:
        by_label = galileo_satellites.sat_id(name)
        by_table = galileo_satellites.sat_id(name.split("(")[0] + "(GALILEO)")  # the GSAT number alone
        assert by_label == by_table, name
    assert galileo_satellites.sat_id("GSAT0101 (GALILEO-PFM)") == "E11"
    assert galileo_satellites.sat_id("GSAT0210 (GALILEO 13)") == "E01"
    assert galileo_satellites.sat_id("GSAT0223") is None  # launched after the table's source
    assert galileo_satellites.sat_id("GSAT0223 (PRN E34)") == "E34"
    assert galileo_satellites.sat_id("COSMOS 2425 (716)") is None


def test_table_agrees_with_broadcast_orbits_eccentric_pair_and_planes():
    tle = {galileo_satellites.sat_id(n): v for n, v in _tle_elements().items()}
    eph = load(NAV, systems="E")
    pos, _, vel, _ = eph.state(2416, 129600.0, velocity=True)
    ok = np.isfinite(pos[:, 0])
    ids = [s for s, good in zip(eph.sat_ids, ok) if good and s in tle]
    assert len(ids) >= 20
    r = pos[[eph.sat_ids.index(s) for s in ids]]
    v = vel[[eph.sat_ids.index(s) for s in ids]] + np.cross([0.0, 0.0, OMEGA_E], r)  # inertial velocity
    h = np.cross(r, v)
    # eccentricity from every broadcast record (E14/E18 are flagged unhealthy in this file, so have no state)
    e = eph.records.params[:, kepler.COL["e"]]
    eccentric_brdc = {eph.sat_ids[k] for k in np.unique(eph.records.sat[e > 0.1])}
    eccentric_tle = {s for s, (_, ecc) in tle.items() if ecc > 0.1}
    assert eccentric_brdc == {"E14", "E18"} and eccentric_tle == {"E14", "E18"}
    # same plane in 2026 (normals within 5 deg) <=> same plane in 2020 (TLE nodes within 5 deg)
    n = h / np.linalg.norm(h, axis=1)[:, None]
    same_2026 = np.degrees(np.arccos(np.clip(n @ n.T, -1, 1))) < 5.0
    raan = np.array([tle[s][0] for s in ids])
    gap = np.abs((raan[:, None] - raan[None, :] + 180.0) % 360.0 - 180.0)
    same_2020 = gap < 5.0
    regular = ~np.isin(ids, ["E14", "E18"])  # the eccentric pair's plane is its own
    assert np.array_equal(same_2026[np.ix_(regular, regular)], same_2020[np.ix_(regular, regular)])
    assert same_2026[np.ix_(regular, regular)].sum(axis=1).min() >= 5  # every plane holds several satellites


def test_sgp4_states_are_galileo_orbits_and_sky_runs():
    c = load(TLE)
    assert c.kind == "tle" and len(c) == 26 and set(c.system) == {"E"}
    pos, clk = c.state(2102, 345600.0)  # 2020-04-22 00:00 GPST, inside every TLE's validity
    radius = np.linalg.norm(pos, axis=1)
    regular = ~np.isin(c.sat_ids, ["E14", "E18"])
    # circular Galileo orbits: a = 29,600.3 km (OS SDD); SGP4 mean -> osculating radius within ~0.1 %
    assert np.all(np.abs(radius[regular] / 29_600.318e3 - 1) < 2e-3)
    assert np.all((radius[~regular] > 23_000e3) & (radius[~regular] < 33_000e3))
    assert np.all(clk == 0.0)
    run = subprocess.run([sys.executable, "-m", "simkit", "sky", str(TLE), "--lat", "50.8", "--lon", "4.4",
                          "--start", "2020-04-22T00:00:00", "--hours", "1", "--step", "1800"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "E" in run.stdout


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.replace("(PRN E", "(XYZ ").replace("GSAT0", "SAT0"), "no GPS, BDS or Galileo satellite"),
    (lambda t: t.replace("0004609 343.6468", "0004609 343.6469"), "checksum mismatch"),
    (lambda t: t[: t.index("2 37847")], "TLE is truncated: expected line 2"),
])
def test_malformed_galileo_tle_is_one_line(tmp_path, edit, message):
    bad = tmp_path / "galileo.txt"
    bad.write_text(edit(TLE.read_text()))
    with pytest.raises(Exception) as info:
        load(bad)
    assert message in str(info.value) and str(bad) in str(info.value) and "\n" not in str(info.value)


def test_validate_runs_on_the_galileo_tle_sky():
    run = subprocess.run([sys.executable, "-m", "simkit", "validate", "quickstart", "--systems", "E", "--no-progress",
                          "--set", f"gnss.constellation[0].source='{TLE}'",
                          "--set", "scenario.start='2020-04-22T00:00:00Z'",
                          "--set", 'gnss.signals=["L1C","B1I","E1C"]'], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "C4: held" in run.stdout and "C5: held" in run.stdout
