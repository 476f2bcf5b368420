"""Broadcast-ephemeris orbits and clocks against RTKLIB's eph2pos (pyrtklib), GPS and BDS GEO/IGSO/MEO.

Referee facts (pyrtklib's behaviour): readrnx needs an uncompressed file; for BDS, RTKLIB keeps toe/toc in
GPST; eph2pos takes GPST for every system; it decides GEO from the PRN (C01-C05, C59+), we from the orbit, so
the agreement also checks our orbit-based GEO decision. RTKLIB is not used on RINEX 4 files.
"""
import gzip
import shutil
from pathlib import Path

import numpy as np
import pytest

from simkit.constellation import kepler, load

import pyrtklib
from conftest import DATA as _DATA

DATA = _DATA / "rinex_nav"
GPS_1980_UNIX = 315964800  # RTKLIB gtime_t counts GPST seconds from 1970-01-01
FILES = ["BRDM00DLR_S_20261170000_01D_MN.rnx.gz", "BRDC00WRD_U_20161580000_01D_MN.rnx", "cubb1870.15c"]


def _rtklib_nav(src: Path, tmp_path: Path):
    plain = tmp_path / src.name.removesuffix(".gz")
    if src.suffix == ".gz":
        with gzip.open(src) as fi, open(plain, "wb") as fo:
            shutil.copyfileobj(fi, fo)
    else:
        shutil.copy(src, plain)
    nav, obs, sta = pyrtklib.nav_t(), pyrtklib.obs_t(), pyrtklib.sta_t()
    assert pyrtklib.readrnx(str(plain), 1, "", obs, nav, sta) == 1
    return nav


def _sat_id(sat):
    buf = pyrtklib.Arr1Dchar(8)
    pyrtklib.satno2id(sat, buf)
    return buf[0]  # element 0 reads the C string up to its NUL


@pytest.mark.parametrize("name", FILES)
def test_eph2pos_agreement(name, tmp_path):
    src = DATA / name
    const = load(src)
    nav = _rtklib_nav(src, tmp_path)
    p = const.records.params
    c = kepler.COL
    toe_abs = const.ref_week * 604800.0 + p[:, c["toe"]]
    ids = np.array(const.sat_ids)[const.records.sat]
    rs, dts, var = pyrtklib.Arr1Ddouble(6), pyrtklib.Arr1Ddouble(2), pyrtklib.Arr1Ddouble(1)
    offsets = np.array([-3600.0, -1234.5, 0.0, 900.0, 3599.0])
    ours_idx, ours_t, ref_pos, ref_clk, kinds = [], [], [], [], []
    for i in range(nav.n):
        eph = nav.eph[i]
        sid = _sat_id(eph.sat)
        if sid[0] not in "GC":
            continue
        t_abs = eph.toe.time - GPS_1980_UNIX + eph.toe.sec
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
    pos, clk = kepler.propagate(p, np.array(ours_idx), np.array(ours_t))
    dpos = np.linalg.norm(pos - np.array(ref_pos), axis=1)
    dclk = np.abs(clk - np.array(ref_clk))
    kinds = np.array(kinds)
    for kind in np.unique(kinds):
        m = kinds == kind
        print(f"{name} {kind}: {m.sum()} evaluations, max |dpos| {dpos[m].max():.2e} m, "
              f"max |dclk| {dclk[m].max():.2e} s")
    assert dpos.max() < 1e-3
    assert dclk.max() < 1e-12
    expected = {"BRDM00DLR_S_20261170000_01D_MN.rnx.gz": {"GMEO", "CGEO", "CIGSO", "CMEO"},
                "BRDC00WRD_U_20161580000_01D_MN.rnx": {"GMEO", "CGEO", "CIGSO", "CMEO"},
                "cubb1870.15c": {"CGEO", "CIGSO", "CMEO"}}[name]
    assert expected <= set(kinds.tolist())
