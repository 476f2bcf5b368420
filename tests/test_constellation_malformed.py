"""Malformed or truncated inputs: one DataFileError naming the file and line; never a partial constellation."""
import gzip
from pathlib import Path

import pytest

from simkit.constellation import load
from simkit.constellation.sources import DATA_DIR
from simkit.errors import DataFileError

RNX = DATA_DIR / "BRDC00WRD_U_20161580000_01D_MN.rnx.gz"
YUMA = DATA_DIR / "almanac.yuma.week0149.405504.txt"
SEM = DATA_DIR / "orekit_current_week0862.al3"
TLE = DATA_DIR / "gps-ops_2022-02-04.txt"


def _lines(path: Path) -> list[str]:
    raw = path.read_bytes()
    return (gzip.decompress(raw) if raw[:2] == b"\x1f\x8b" else raw).decode().splitlines()


def _write(tmp_path, name, lines):
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


def _error(path) -> DataFileError:
    with pytest.raises(DataFileError) as info:
        load(path)
    assert str(path) in str(info.value)
    return info.value


def test_rinex_truncated_in_the_middle_of_a_record(tmp_path):
    lines = _lines(RNX)
    for system in "GRC":  # GPS, a skipped system (GLONASS) and BDS records are all checked
        k = [i for i, ln in enumerate(lines) if ln.startswith(system)][3]
        err = _error(_write(tmp_path, f"cut{system}.rnx", lines[:k + 3]))  # file ends inside a record
        assert err.line == k + 1  # the record's first line
        assert "expected" in err.message and "truncated" in err.message


def test_rinex_bad_number_names_its_line(tmp_path):
    lines = _lines(RNX)
    k = next(i for i, ln in enumerate(lines) if ln.startswith("G")) + 2
    lines[k] = lines[k][:23] + "   1.2345X678901e+03" + lines[k][42:]
    err = _error(_write(tmp_path, "bad.rnx", lines))
    assert err.line == k + 1 and "expected a number" in err.message


def test_rinex_missing_end_of_header_and_truncated_gzip(tmp_path):
    lines = [ln for ln in _lines(RNX) if "END OF HEADER" not in ln][:50]
    err = _error(_write(tmp_path, "nohdr.rnx", lines))
    assert "END OF HEADER" in err.message
    raw = RNX.read_bytes()
    path = tmp_path / "cut.rnx.gz"
    path.write_bytes(raw[: len(raw) // 2])
    assert "gzip" in _error(path).message


def test_rinex_record_cut_by_the_next_record(tmp_path):
    lines = _lines(RNX)
    k = next(i for i, ln in enumerate(lines) if ln.startswith("G"))
    del lines[k + 5]
    err = _error(_write(tmp_path, "short.rnx", lines))
    assert err.line == k + 1 and "expected 8" in err.message


def test_yuma_truncated_and_bad_value(tmp_path):
    lines = _lines(YUMA)
    err = _error(_write(tmp_path, "cut.yuma", lines[:-5]))
    assert "missing" in err.message and err.line is not None
    lines[5] = lines[5].split(":")[0] + ":  0.98x"
    err = _error(_write(tmp_path, "bad.yuma", lines))
    assert err.line == 6


def test_sem_truncated(tmp_path):
    err = _error(_write(tmp_path, "cut.al3", _lines(SEM)[:-7]))
    assert "header announces" in err.message and err.line is not None


def test_tle_checksum_and_truncation(tmp_path):
    lines = _lines(TLE)
    bad = list(lines)
    bad[1] = bad[1][:20] + ("1" if bad[1][20] != "1" else "2") + bad[1][21:]
    err = _error(_write(tmp_path, "bad.tle", bad))
    assert err.line == 2 and "checksum" in err.message
    err = _error(_write(tmp_path, "cut.tle", lines[:-1]))
    assert "truncated" in err.message


def test_unknown_format_missing_file_and_unknown_nominal(tmp_path):
    err = _error(_write(tmp_path, "notes.txt", ["hello", "world"]))
    assert "unknown format" in err.message
    with pytest.raises(DataFileError, match="no such file"):
        load(tmp_path / "absent.rnx")
    with pytest.raises(DataFileError, match="nominal:gps"):
        load("nominal:galileo")


RNX2 = Path(__file__).parent / "data" / "rinex_nav" / "brdc0010.21n"   # RINEX 2.11 GPS (tests/data/SOURCES.md)


def _first_record(lines) -> int:
    return next(i for i, ln in enumerate(lines) if "END OF HEADER" in ln) + 1


@pytest.mark.parametrize("edit, words", [
    (lambda ln: ln[:2] + " 2O" + ln[5:], "RINEX 2 satellite number and epoch"),      # a letter in the year
    (lambda ln: ln[:17] + " 12.5" + ln[22:], "not whole"),                        # a clock epoch off the second
    (lambda ln: ln[:22] + "-5.6086713X4817D-04" + ln[41:], "expected a number"),  # a bad clock term
])
def test_rinex2_bad_record_start_names_its_line(tmp_path, edit, words):
    lines = _lines(RNX2)
    k = _first_record(lines) + 8 * 5        # the sixth record's first line
    lines[k] = edit(lines[k])
    err = _error(_write(tmp_path, "bad.21n", lines))
    assert err.line == k + 1 and words in err.message


def test_rinex2_truncated_record_and_header(tmp_path):
    lines = _lines(RNX2)
    k = _first_record(lines) + 8 * 3
    err = _error(_write(tmp_path, "cut.21n", lines[:k + 5]))   # the file ends inside the fourth record
    assert err.line == k + 1 and "truncated" in err.message
    h = next(i for i, ln in enumerate(lines) if ln[60:].strip() == "ION BETA")
    lines[h] = lines[h][:26] + " " * 12 + lines[h][38:]                 # a blank third beta coefficient
    err = _error(_write(tmp_path, "beta.21n", lines))
    assert err.line == h + 1 and "ION BETA coefficient 2" in err.message
    lines[0] = "     1.00" + lines[0][9:]
    assert "2.1x, 3.0x or 4.0x" in _error(_write(tmp_path, "v1.21n", lines)).message
