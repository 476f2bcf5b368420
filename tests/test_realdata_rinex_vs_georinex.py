"""The RINEX observation reader against georinex (an independent reader) on real receiver files.

Every value, loss-of-lock and signal-strength indicator of every GPS and BDS observation type, and every epoch
time, must be the same. georinex reads RINEX 2 and 3 only: the RINEX 4.00 KMS3 file (Hatanaka) is expanded and
handed to georinex relabelled as 3.05, whose observation records have the same format.
"""
from __future__ import annotations

import warnings
from datetime import datetime, timedelta
from pathlib import Path

import numpy as np
import pytest

from simkit import gpstime
from simkit.gnss import rinex_obs

georinex = pytest.importorskip("georinex")
DATA = Path(__file__).parent / "data" / "rinex_obs"
FILES = ["solo0150.16o", "ACOR00ESP_R_20213550000_8ep_30S_MO.rnx", "UrbanNav-HK-Medium-Urban-1_30ep.obs",
         "Berlin_Potsdamer_Platz_60ep.obs"]


def _georinex(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return georinex.load(path, useindicators=True)


def _compare(ours: rinex_obs.ObsFile, ref, v2: bool):
    week, sow = ours.start
    t0 = gpstime.GPS_EPOCH.replace(tzinfo=None) + timedelta(weeks=week, seconds=sow)
    ref_t = np.array([(datetime.fromisoformat(str(x)[:26]) - t0).total_seconds() for x in ref.time.values])
    np.testing.assert_allclose(ours.t, ref_t, atol=1e-3)  # georinex keeps whole milliseconds (42.3999998 s -> .399)
    svs = [str(s) for s in ref.sv.values]
    checked = 0
    for sys in ("G", "C"):
        if sys not in ours.systems:
            continue
        so = ours.systems[sys]
        for name in ref.data_vars:
            if name.endswith(("lli", "ssi")):
                continue
            code = rinex_obs._v2_code(sys, name, ours.header.version) if v2 else name
            if code not in so.types:
                continue
            k = so.types.index(code)
            for j, sat in enumerate(so.sats):
                if sat not in svs:
                    assert np.isnan(so.values[:, j, k]).all()
                    continue
                theirs = ref[name].sel(sv=sat).values.astype(float)
                np.testing.assert_array_equal(so.values[:, j, k], theirs, err_msg=f"{sat} {code}")
                if f"{name}lli" in ref:
                    lli = np.nan_to_num(ref[f"{name}lli"].sel(sv=sat).values.astype(float)).astype(int)
                    np.testing.assert_array_equal(so.lli[:, j, k], lli, err_msg=f"{sat} {code} LLI")
                if f"{name}ssi" in ref:
                    ssi = np.nan_to_num(ref[f"{name}ssi"].sel(sv=sat).values.astype(float)).astype(int)
                    np.testing.assert_array_equal(so.ssi[:, j, k], ssi, err_msg=f"{sat} {code} SSI")
                checked += int(np.isfinite(theirs).sum())
    return checked


@pytest.mark.parametrize("name", FILES)
def test_every_gps_and_bds_value_matches_georinex(name):
    path = DATA / name
    ours = rinex_obs.read(path)
    checked = _compare(ours, _georinex(path), ours.header.version < 3)
    assert checked > 100


def test_rinex4_hatanaka_file_matches_georinex_relabelled(tmp_path):
    ours = rinex_obs.read(DATA / "KMS300DNK_R_20221591000_01H_30S_MO.crx")
    assert ours.header.version == 4.0 and ours.t.size == 19
    text = rinex_obs.decompress(DATA / "KMS300DNK_R_20221591000_01H_30S_MO.crx").decode("latin-1")
    assert text.startswith("     4.00")
    relabelled = tmp_path / "kms3_as_305.rnx"
    relabelled.write_text("     3.05" + text[9:], encoding="latin-1")
    assert _compare(ours, _georinex(relabelled), False) > 1000


def test_signal_mapping_follows_the_signal_table():
    assert rinex_obs.signal_name("G", "C1C", 3.04) == "L1C"
    assert rinex_obs.signal_name("G", "L2W", 3.04) == "L2W"
    assert rinex_obs.signal_name("G", "C1W", 3.04) is None          # P(Y) on L1: not a simkit signal
    assert rinex_obs.signal_name("C", "C2I", 3.04) == "B1I"
    assert rinex_obs.signal_name("C", "C1I", 3.02) == "B1I"          # RINEX 3.02 wrote B1I with band 1
    assert rinex_obs.signal_name("C", "C1X", 3.04) is None           # B1C data+pilot: not simkit's B1C (pilot)
    assert rinex_obs.signal_name("C", "L1P", 4.00) == "B1C"
    assert rinex_obs.signal_name("C", "C6I", 3.04) == "B3I"
    assert rinex_obs.signal_name("R", "C1C", 3.04) == "G1C"          # GLONASS G1 C/A (FDMA)
    assert rinex_obs.signal_name("E", "C5Q", 3.04) == "E5aQ"
    assert rinex_obs.signal_name("J", "C1C", 3.04) == "J1C"          # QZSS L1 C/A: its own name
    assert rinex_obs.signal_name("S", "C1C", 3.04) is None           # SBAS: not simulated


def test_rinex2_glonass_types_follow_the_tracked_code():
    """RINEX 2.11 sec. 5.1: C1/C2 are the C/A codes, P1/P2 the P codes; a phase (Doppler, strength) belongs to the
    C/A code unless the band has a P code (on G1: and no C/A code), since a P-code phase is a quarter cycle off."""
    f = rinex_obs._v2_code
    assert [f("R", c, 2.11, ["C1", "L1", "S1", "D1"]) for c in ("C1", "L1", "S1", "D1")] == ["C1C", "L1C", "S1C", "D1C"]
    geodetic = ["C1", "P1", "L1", "P2", "L2"]
    assert [f("R", c, 2.11, geodetic) for c in geodetic] == ["C1C", "C1P", "L1C", "C2P", "L2P"]
    assert [f("R", c, 2.11, ["C1", "C2", "L2"]) for c in ("C2", "L2")] == ["C2C", "L2C"]
    assert f("R", "L1", 2.11, ["P1", "L1"]) == "L1P"
    assert [rinex_obs.signal_name("R", f("R", c, 2.11, geodetic), 2.11) for c in geodetic] == ["G1C", None, "G1C",
                                                                                               None, None]
