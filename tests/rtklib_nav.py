"""RTKLIB's reading of a RINEX navigation file, and the comparison of simkit's Kepler orbits with its eph2pos,
for the constellation tests that check simkit against RTKLIB (pyrtklib; /work/shared/notes/pyrtklib.md)."""
from __future__ import annotations

import gzip
import shutil
from pathlib import Path

import numpy as np
import pyrtklib

from simkit.constellation import kepler

GPS_1980_UNIX = 315964800  # RTKLIB gtime_t counts GPST seconds from 1970-01-01


def rtklib_nav(src: Path, tmp_path: Path):
    """RTKLIB's ``nav_t`` of navigation file ``src`` (gzip expanded into ``tmp_path`` first)."""
    plain = tmp_path / src.name.removesuffix(".gz")
    if src.suffix == ".gz":
        with gzip.open(src) as fi, open(plain, "wb") as fo:
            shutil.copyfileobj(fi, fo)
    else:
        shutil.copy(src, plain)
    nav, obs, sta = pyrtklib.nav_t(), pyrtklib.obs_t(), pyrtklib.sta_t()
    assert pyrtklib.readrnx(str(plain), 1, "", obs, nav, sta) == 1
    return nav


def sat_id(sat) -> str:
    """RTKLIB satellite number -> "G01"."""
    buf = pyrtklib.Arr1Dchar(8)
    pyrtklib.satno2id(sat, buf)
    return buf[0]  # element 0 reads the C string up to its NUL


def gpst(t) -> float:
    """RTKLIB gtime_t -> GPS seconds since 1980-01-06."""
    return t.time - GPS_1980_UNIX + t.sec


def kepler_against_rtklib(params, idx, t, ref_pos, ref_clk, kinds, label: str, per: int = 1):
    """simkit's Kepler states of records ``idx`` at times ``t`` (s of the records' week) against RTKLIB's
    ``ref_pos`` (m) and ``ref_clk`` (s); prints the worst per orbit kind (``per`` evaluations per record) and
    returns (|dpos| m, |dclk| s, kinds) as arrays."""
    pos, clk = kepler.propagate(params, np.array(idx), np.array(t))
    dpos = np.linalg.norm(pos - np.array(ref_pos), axis=1)
    dclk = np.abs(clk - np.array(ref_clk))
    kinds = np.array(kinds)
    for kind in np.unique(kinds):
        m = kinds == kind
        count = f"{m.sum() // per} records" if per > 1 else f"{m.sum()} evaluations"
        print(f"{label} {kind}: {count}, max |dpos| {dpos[m].max():.2e} m, max |dclk| {dclk[m].max():.2e} s")
    return dpos, dclk, kinds
