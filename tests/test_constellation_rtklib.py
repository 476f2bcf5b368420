"""Broadcast-ephemeris orbits and clocks against RTKLIB's eph2pos (pyrtklib), GPS and BDS GEO/IGSO/MEO.

Referee facts (pyrtklib's behaviour): readrnx needs an uncompressed file; for BDS, RTKLIB keeps toe/toc in
GPST; eph2pos takes GPST for every system; it decides GEO from the PRN (C01-C05, C59+), we from the orbit, so
the agreement also checks our orbit-based GEO decision. RTKLIB is not used on RINEX 4 files.
"""
import numpy as np
import pytest

from simkit.constellation import kepler, load

import pyrtklib
from conftest import DATA as _DATA
from rtklib_nav import gpst, kepler_against_rtklib, rtklib_nav, sat_id

DATA = _DATA / "rinex_nav"
FILES = ["BRDM00DLR_S_20261170000_01D_MN.rnx.gz", "BRDC00WRD_U_20161580000_01D_MN.rnx", "cubb1870.15c",
         "brdc0010.21n"]


@pytest.mark.parametrize("name", FILES)
def test_eph2pos_agreement(name, tmp_path):
    src = DATA / name
    const = load(src)
    nav = rtklib_nav(src, tmp_path)
    p = const.records.params
    c = kepler.COL
    toe_abs = const.ref_week * 604800.0 + p[:, c["toe"]]
    ids = np.array(const.sat_ids)[const.records.sat]
    rs, dts, var = pyrtklib.Arr1Ddouble(6), pyrtklib.Arr1Ddouble(2), pyrtklib.Arr1Ddouble(1)
    offsets = np.array([-3600.0, -1234.5, 0.0, 900.0, 3599.0])
    ours_idx, ours_t, ref_pos, ref_clk, kinds = [], [], [], [], []
    for i in range(nav.n):
        eph = nav.eph[i]
        sid = sat_id(eph.sat)
        if sid[0] not in "GC":
            continue
        t_abs = gpst(eph.toe)
        match = np.flatnonzero((ids == sid) & (toe_abs == t_abs) & (p[:, c["af0"]] == eph.f0))
        assert match.size >= 1, f"{sid} toe {t_abs}: record missing from our table"
        k = match[0]
        for dt in offsets * (0.5 if sid[0] == "C" else 1.0):
            pyrtklib.eph2pos(pyrtklib.timeadd(eph.toe, float(dt)), eph, rs, dts, var)
            ours_idx.append(k)
            ours_t.append(p[k, c["toe"]] + dt)
            ref_pos.append([rs[0], rs[1], rs[2]])
            ref_clk.append(dts[0])
            kinds.append(sid[0] + const.orbit_type[const.records.sat[k]])
    dpos, dclk, kinds = kepler_against_rtklib(p, ours_idx, ours_t, ref_pos, ref_clk, kinds, name)
    assert dpos.max() < 1e-3
    assert dclk.max() < 1e-12
    expected = {"BRDM00DLR_S_20261170000_01D_MN.rnx.gz": {"GMEO", "CGEO", "CIGSO", "CMEO"},
                "BRDC00WRD_U_20161580000_01D_MN.rnx": {"GMEO", "CGEO", "CIGSO", "CMEO"},
                "cubb1870.15c": {"CGEO", "CIGSO", "CMEO"}, "brdc0010.21n": {"GMEO"}}[name]
    assert expected <= set(kinds.tolist())


def test_rinex2_header_klobuchar_and_utc_as_rtklib_reads_them(tmp_path):
    """ION ALPHA / ION BETA and DELTA-UTC of a RINEX 2.11 GPS file: the coefficients RTKLIB's readrnx keeps."""
    src = DATA / "brdc0010.21n"
    const = load(src)
    nav = rtklib_nav(src, tmp_path)
    k = const.klobuchar["G"]
    np.testing.assert_array_equal(np.concatenate([k.alpha, k.beta]), [nav.ion_gps[i] for i in range(8)])
    utc = const.time_offsets["GPUT"]
    assert (utc.a0, utc.a1, utc.t_ref[1], utc.t_ref[0]) == tuple(nav.utc_gps[i] for i in range(4))
