"""Malformed Galileo / QZSS / GLONASS navigation records: one DataFileError naming the file, the line and what was
expected; never a partial constellation."""
import gzip

import pytest

from simkit.constellation import load
from simkit.constellation.sources import DATA_DIR
from simkit.errors import DataFileError

BRDM = DATA_DIR / "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"
KMS3 = DATA_DIR / "KMS300DNK_R_20221591000_01H_MN.rnx.gz"


def _lines(path):
    return gzip.decompress(path.read_bytes()).decode().splitlines()


def _write(tmp_path, name, lines):
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


def _error(path, match):
    with pytest.raises(DataFileError, match=match) as info:
        load(path)
    assert str(path) in str(info.value)
    return info.value


def _first(lines, prefix, n=0):
    return [i for i, ln in enumerate(lines) if ln.startswith(prefix)][n]


def test_glonass_frequency_number_out_of_range(tmp_path):
    lines = _lines(BRDM)
    k = _first(lines, "R05")
    lines[k + 2] = lines[k + 2][:61] + f"{19.0:19.12e}"
    err = _error(_write(tmp_path, "frq.rnx", lines), r"GLONASS frequency number 19: expected -7\.\.13")
    assert err.line == k + 3


def test_glonass_records_of_one_satellite_disagree_on_the_channel(tmp_path):
    lines = _lines(BRDM)
    k = _first(lines, "R05", 1)
    lines[k + 2] = lines[k + 2][:61] + f"{2.0:19.12e}"
    _error(_write(tmp_path, "two.rnx", lines), "R05: records give different frequency numbers")


def test_glonass_missing_position_is_named(tmp_path):
    lines = _lines(BRDM)
    k = _first(lines, "R07")
    lines[k + 1] = " " * 4 + " " * 19 + lines[k + 1][23:]
    err = _error(_write(tmp_path, "pos.rnx", lines), "missing GLONASS orbit value 1")
    assert err.line == k + 2


def test_rinex4_fdma_record_cut_short(tmp_path):
    lines = _lines(KMS3)
    k = _first(lines, "> EPH R")
    cut = lines[:k + 3] + lines[k + 6:]
    err = _error(_write(tmp_path, "fdma.rnx", cut), "FDMA record for R.. has 2 lines, expected 5")
    assert err.line is not None


def test_galileo_record_with_a_bad_number(tmp_path):
    lines = _lines(BRDM)
    k = _first(lines, "E11")
    lines[k + 2] = lines[k + 2][:4] + "   1.2.3e+00xxxxxx" + lines[k + 2][22:]
    err = _error(_write(tmp_path, "gal.rnx", lines), "expected a number")
    assert err.line == k + 3


def test_no_record_of_the_systems_asked():
    cubb = DATA_DIR / "cubb1870.15c.gz"  # a BDS-only RINEX 3 file
    with pytest.raises(DataFileError, match="no broadcast ephemeris records found for Galileo, GLONASS"):
        load(cubb, systems="ER")
