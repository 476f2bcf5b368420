"""Shared helpers of the real-data tests: the test copies of the real files and RTKLIB (pyrtklib) SPP runs."""
from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np

ROOT = Path(__file__).parents[1]
OBS = ROOT / "tests" / "data" / "rinex_obs"
NAV = ROOT / "simkit" / "data"
KMS3_OBS = OBS / "KMS300DNK_R_20221591000_01H_30S_MO.crx"
KMS3_NAV = NAV / "KMS300DNK_R_20221591000_01H_MN.rnx.gz"
BERLIN_OBS = OBS / "Berlin_Potsdamer_Platz_60ep.obs"
BERLIN_NAV = NAV / "BRDC00WRD_U_20161580000_01D_MN.rnx.gz"
CN00_OBS = OBS / "cn000010.21o"            # 24 h of a static CORS station with C/N0 (tests/data/SOURCES.md)
CN00_NAV = ROOT / "tests" / "data" / "rinex_nav" / "brdc0010.21n"   # its day's RINEX 2.11 GPS broadcast file
KMS3_HEADER_POS = np.array([3516213.4380, 781859.8595, 5246037.9660])  # APPROX POSITION XYZ, delta H/E/N zero


def cn00_first_epochs(dst, n: int) -> Path:
    """The header and the first ``n`` epoch records of CN00's file, byte for byte (a shorter file for a test)."""
    lines = CN00_OBS.read_bytes().split(b"\r\n")
    starts = [i for i, ln in enumerate(lines) if ln.startswith(b" 21  1  1 ")]
    Path(dst).write_bytes(b"\r\n".join(lines[:starts[n]]) + b"\r\n")
    return Path(dst)


def rinex4_nav_as_rinex3(src, dst) -> Path:
    """A RINEX 4.00 navigation file rewritten as RINEX 3.04 for RTKLIB 2.4.3 (which reads RINEX 4 CNAV records as
    LNAV ones: docs of notes/pyrtklib.md): the GPS LNAV and BDS D1/D2 records' 8 lines unchanged, the ``> ION``
    Klobuchar records (G LNAV, C D1D2) as GPSA/GPSB/BDSA/BDSB header lines; every other record dropped."""
    lines = gzip.decompress(Path(src).read_bytes()).decode("latin-1").splitlines()
    head = [f"{'3.04':>9}{'':11}{'N: GNSS NAV DATA':<20}{'M: MIXED':<20}RINEX VERSION / TYPE"]
    body = []
    i = 0
    while i < len(lines):
        parts = lines[i].split()
        if lines[i].startswith("> EPH") and parts[3] in ("LNAV", "D1", "D2") and parts[2][0] in "GC":
            body += lines[i + 1:i + 9]
            i += 9
            continue
        if lines[i].startswith("> ION") and (parts[2][0], parts[3]) in (("G", "LNAV"), ("C", "D1D2")):
            rec = lines[i + 1:i + 4]
            vals = [rec[0][23 + 19 * k:42 + 19 * k] for k in range(3)] + [rec[1][4 + 19 * k:23 + 19 * k]
                                                                            for k in range(4)] + [rec[2][4:23]]
            vals = [float(v.replace("D", "E")) for v in vals]
            tag = "GPS" if parts[2][0] == "G" else "BDS"
            for ab, four in (("A", vals[:4]), ("B", vals[4:8])):
                head.append(f"{tag}{ab} " + "".join(f"{v:12.4E}" for v in four).ljust(55) + "IONOSPHERIC CORR")
            i += 4
            continue
        i += 1
    head.append(" " * 60 + "END OF HEADER")
    Path(dst).write_text("\n".join(head + body) + "\n")
    return Path(dst)


def rtklib_spp(obs, nav, out, navsys, ionoopt, nf=1, elmin_deg=10.0):
    """RTKLIB single-point solutions (pyrtklib postpos, PMODE_SINGLE, Saastamoinen troposphere): GPS seconds of
    week (K,) and ECEF positions (K, 3) m."""
    import pyrtklib as rtk

    popt, sopt = rtk.prcopt_default, rtk.solopt_default
    popt.mode, popt.navsys, popt.nf = rtk.PMODE_SINGLE, navsys, nf
    popt.elmin = np.radians(elmin_deg)
    popt.ionoopt, popt.tropopt = ionoopt, rtk.TROPOPT_SAAS
    sopt.posf, sopt.timef = rtk.SOLF_XYZ, 0
    buf = rtk.Arr1Dchar(1024)
    for i, c in enumerate(str(out) + "\0"):
        buf[i] = c
    files = [str(obs), str(nav)]
    assert rtk.postpos(rtk.gtime_t(), rtk.gtime_t(), 0.0, 0.0, popt, sopt, rtk.filopt_t(), files, 2, buf, "",
                       "") == 0
    rows = [ln.split() for ln in open(out) if not ln.startswith("%")]
    return np.array([float(r[1]) for r in rows]), np.array([[float(x) for x in r[2:5]] for r in rows])
