"""Bad and odd RINEX observation input: one clear line each (file, line, what was expected), or a note.

Small files are written from a valid template and changed in one place each.
"""
from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest

from simkit.cli import main
from simkit.errors import DataFileError, InputError
from simkit.gnss import rinex_obs
from simkit.realdata import importer

DATA = Path(__file__).parent / "data" / "rinex_obs"
NAV_2016 = Path(__file__).parents[1] / "simkit" / "data" / "BRDC00WRD_U_20161580000_01D_MN.rnx.gz"


def _h(text, label):
    return f"{text:<60}{label}"


HEADER = [
    _h("     3.04           OBSERVATION DATA    M", "RINEX VERSION / TYPE"),
    _h("KMS3", "MARKER NAME"),
    _h("  3516213.4380   781859.8595  5246037.9660", "APPROX POSITION XYZ"),
    _h("        0.0000        0.0000        0.0000", "ANTENNA: DELTA H/E/N"),
    _h("G    3 C1C L1C S1C", "SYS / # / OBS TYPES"),
    _h("C    2 C2I L2I", "SYS / # / OBS TYPES"),
    _h("  2016     6     6    11     0    0.0000000     GPS", "TIME OF FIRST OBS"),
    _h("", "END OF HEADER"),
]
BODY = [
    "> 2016 06 06 11 00 00.0000000  0  2",
    "G05  21000000.123 7 110355000.456 7        45.000",
    "C01  38000000.000 6 197000000.250 6",
    "> 2016 06 06 11 00 30.0000000  0  2",
    "G05  21000300.123 7 110356600.456 7        45.250",
    "C01  38000001.000 6 197000010.250 6",
]


def _write(tmp_path, header=HEADER, body=BODY, name="x.rnx"):
    path = tmp_path / name
    path.write_text("\n".join(header + body) + "\n", encoding="latin-1")
    return path


def _error(path) -> str:
    with pytest.raises(DataFileError) as exc:
        rinex_obs.read(path)
    text = str(exc.value)
    assert "\n" not in text and str(path) in text
    return text


def test_the_template_reads(tmp_path):
    obs = rinex_obs.read(_write(tmp_path))
    assert obs.t.tolist() == [0.0, 30.0] and obs.notes == []
    g = obs.systems["G"]
    assert g.sats == ["G05"] and g.values[1, 0].tolist() == [21000300.123, 110356600.456, 45.25]
    assert g.ssi[0, 0].tolist() == [7, 7, 0] and g.lli.max() == 0 and obs.systems["C"].values.shape == (2, 1, 2)


def test_gzip_is_read_like_plain(tmp_path):
    plain = _write(tmp_path)
    packed = tmp_path / "x.rnx.gz"
    packed.write_bytes(gzip.compress(plain.read_bytes()))
    a, b = rinex_obs.read(plain), rinex_obs.read(packed)
    np.testing.assert_array_equal(a.systems["G"].values, b.systems["G"].values)


@pytest.mark.parametrize("change, expected", [
    (lambda h, b: (["     5.00" + h[0][9:]] + h[1:], b), "RINEX version 5 is not supported"),
    (lambda h, b: ([h[0][:20] + "N" + h[0][21:]] + h[1:], b), "is a navigation file"),
    (lambda h, b: ([x for x in h if "OBS TYPES" not in x], b), "missing 'SYS / # / OBS TYPES'"),
    (lambda h, b: (h[:-1], []), "no 'END OF HEADER' line"),
    (lambda h, b: (h[:4] + [_h("G    4 C1C L1C S1C", "SYS / # / OBS TYPES")] + h[5:], b), "announces 4 types, lists 3"),
    (lambda h, b: (h[:6] + [_h("  2016     6     6    11     0    0.0000000     GLO", "TIME OF FIRST OBS")] + h[7:],
                   b), "time system 'GLO'"),
    (lambda h, b: (h, b[:2] + [""] + b[2:]), "blank line where a satellite record was expected"),
    (lambda h, b: (h, b[:3] + [""] + b[3:]), "blank line where an epoch record"),
    (lambda h, b: (h, ["> 2016 06 06 11"] + b[1:]), "bad or truncated epoch line"),
    (lambda h, b: (h, b[:5]), "the file ends after 1"),
    (lambda h, b: (h, ["> 2016 06 06 11 00 00.0000000  0  3"] + b[1:]), "announces 3 satellites but lists 2"),
    (lambda h, b: (h, [b[0], "G05  2100x000.123 7 110355000.456 7"] + b[2:]), "expected an observation value"),
    (lambda h, b: (h, [b[0], "G05  21000000.123x7 110355000.456 7"] + b[2:]), "LLI in column 18"),
    (lambda h, b: (h, [b[0], "G?5  21000000.123 7"] + b[2:]), "bad satellite id 'G?5'"),
    (lambda h, b: (h, b[:1] + ["E11  21000000.123 7"] + b[2:]), "no observation types for system 'E'"),
    (lambda h, b: (h, ["> 2016 06 06 11 00 00.0000000  9  2"] + b[1:]), "epoch flag 9: expected 0-6"),
    (lambda h, b: (h, b[3:] + b[:3]), "not later than the epoch before it"),
    (lambda h, b: (h, ["> 2016 06 06 11 00 00.0000000  4  1", _h("G    2 C1C L1C", "SYS / # / OBS TYPES")] + b),
     "observation types redefined inside the data"),
    (lambda h, b: (h, ["> 2016 06 06 11 00 00.0000000  5  3", "  one record"]), "announces 3 records"),
])
def test_malformed_is_one_line_naming_the_problem(tmp_path, change, expected):
    header, body = change(list(HEADER), list(BODY))
    assert expected in _error(_write(tmp_path, header, body))


def test_the_error_names_the_line(tmp_path):
    body = [BODY[0], "G05  2100x000.123 7 110355000.456 7"] + BODY[2:]
    text = _error(_write(tmp_path, HEADER, body))
    assert f":{len(HEADER) + 2}:" in text and "columns 4-17" in text


@pytest.mark.parametrize("records, note", [
    (["> 2016 06 06 11 00 15.0000000  5  0"], "epoch flag 5 (external event): 1"),
    (["> 2016 06 06 11 00 15.0000000  2  1", _h("moving now", "COMMENT")], "epoch flag 2 (start moving): 1"),
    (["> 2016 06 06 11 00 15.0000000  3  1", _h("KMS4", "MARKER NAME")], "epoch flag 3 (new site occupation)"),
    (["> 2016 06 06 11 00 15.0000000  4  1", _h("a comment", "COMMENT")], "epoch flag 4 (header records)"),
    (["> 2016 06 06 11 00 15.0000000  6  1", "G05  21000150.123 1"], "epoch flag 6 (cycle-slip records, skipped)"),
])
def test_event_records_are_skipped_and_noted(tmp_path, records, note):
    obs = rinex_obs.read(_write(tmp_path, HEADER, BODY[:3] + records + BODY[3:]))
    assert obs.t.tolist() == [0.0, 30.0]
    assert any(n.startswith(note) for n in obs.notes), obs.notes
    assert obs.systems["G"].values[1, 0, 0] == 21000300.123


def test_power_failure_and_clock_offsets_are_noted(tmp_path):
    body = ["> 2016 06 06 11 00 00.0000000  0  2      0.000123456789"] + BODY[1:3] + \
           ["> 2016 06 06 11 00 30.0000000  1  2"] + BODY[4:]
    obs = rinex_obs.read(_write(tmp_path, HEADER, body))
    assert obs.clock_offset_s[0] == pytest.approx(0.000123456789) and np.isnan(obs.clock_offset_s[1])
    assert any("receiver clock offset" in n for n in obs.notes)
    assert any("epoch flag 1 (power failure" in n for n in obs.notes)


def test_bdt_time_tags_become_gps_time(tmp_path):
    header = HEADER[:6] + [_h("  2016     6     6    11     0    0.0000000     BDT", "TIME OF FIRST OBS")] + HEADER[7:]
    gps = rinex_obs.read(_write(tmp_path, HEADER, BODY, "g.rnx"))
    bdt = rinex_obs.read(_write(tmp_path, header, BODY, "c.rnx"))
    assert bdt.start[0] == gps.start[0] and bdt.start[1] - gps.start[1] == 14.0


def test_rinex2_truncated_record_and_missing_types(tmp_path):
    lines = (DATA / "Berlin_Potsdamer_Platz_60ep.obs").read_text(encoding="latin-1").splitlines()
    head = next(i for i, x in enumerate(lines) if "END OF HEADER" in x) + 1
    first_epoch = lines[: head + 1 + 19]  # the first epoch: 19 satellites, one line each
    cut = _write(tmp_path, first_epoch[:-3], [], "cut.obs")
    assert "ends inside an epoch's observation records" in _error(cut)
    no_types = _write(tmp_path, [x for x in lines[:head] if "TYPES OF OBSERV" not in x], lines[head:], "nt.obs")
    assert "missing '# / TYPES OF OBSERV'" in _error(no_types)


def test_navigation_without_a_needed_system(tmp_path):
    gps_only = _write(tmp_path, HEADER, [BODY[0][:-1] + "1", BODY[1], BODY[3][:-1] + "1", BODY[4]], "g.rnx")
    with pytest.raises(DataFileError, match="no broadcast ephemeris for the observed systems G .the navigation "
                                            "data has C"):
        importer.import_rinex(gps_only, [_one_system_nav(tmp_path, keep="C")])
    with pytest.raises(DataFileError, match="no broadcast ephemeris for the observed systems G .the navigation "
                                            "data has R"):
        importer.import_rinex(gps_only, [_one_system_nav(tmp_path, keep="R")])
    partial = importer.import_rinex(_write(tmp_path), [_one_system_nav(tmp_path, keep="G")])
    assert any("without system(s) C" in n for n in partial.report["notes"])
    pos = partial.datasets["gnss/sat_pos_ecef"]
    sats = partial.datasets["gnss/sat_id"].tolist()
    assert np.isfinite(pos[:, sats.index("G05")]).all() and np.isnan(pos[:, sats.index("C01")]).all()


def _one_system_nav(tmp_path, keep: str) -> Path:
    """The 2016 broadcast file with the records of system ``keep`` only (GLONASS 'R': no GPS or BDS at all)."""
    lines = gzip.decompress(NAV_2016.read_bytes()).decode("latin-1").splitlines()
    head = next(i for i, x in enumerate(lines) if "END OF HEADER" in x) + 1
    out, take = lines[:head], False
    for line in lines[head:]:
        if line[:1].strip():
            take = line[0] == keep
        if take:
            out.append(line)
    path = tmp_path / f"nav_{keep}.rnx"
    path.write_text("\n".join(out) + "\n", encoding="latin-1")
    return path


def test_cli_bad_input_is_one_line_and_leaves_nothing(tmp_path, capsys):
    bad = _write(tmp_path, HEADER, BODY[:5])
    out = tmp_path / "real.h5"
    assert main(["import", str(bad), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "simkit import: error:" in err and "the file ends after 1" in err
    assert not out.exists() and list(tmp_path.iterdir()) == [bad]


def test_cli_refuses_to_replace_an_input(tmp_path, capsys):
    good = _write(tmp_path)
    assert main(["import", str(good), "-o", str(good)]) == 2
    assert "is an input of this command" in capsys.readouterr().err
    assert rinex_obs.read(good).t.size == 2


@pytest.mark.parametrize("verb", ["import", "twin"])
@pytest.mark.parametrize("what, expected", [
    ("obs_dir", "folder: is a directory, expected a RINEX observation file"),
    ("obs_missing", "none.obs: no such RINEX observation file"),
    ("nav_dir", "--nav folder: is a directory, expected a RINEX navigation file"),
    ("nav_missing", "--nav none.rnx: no such file, and not a bundled navigation file (bundled: "
                    "BRDC00WRD_U_20161580000_01D_MN.rnx.gz"),
])
def test_missing_or_folder_inputs_are_one_line(tmp_path, verb, what, expected):
    """A folder given as the observation or navigation file is named as one, not as a missing file, and a
    missing navigation file lists the bundled ones `--nav` also takes by name."""
    from cli_errors import assert_clean_error

    good = _write(tmp_path)
    (tmp_path / "folder").mkdir()
    obs = {"obs_dir": "folder", "obs_missing": "none.obs"}.get(what, good.name)
    nav = {"nav_dir": "folder", "nav_missing": "none.rnx"}.get(what, str(NAV_2016))
    assert_clean_error([verb, obs, "--nav", nav, "-o", "out"], tmp_path, expect=expected)


@pytest.mark.parametrize("args, expected", [
    (["--reference", "1,2"], "expected X,Y,Z in metres"),
    (["--reference", "1,2,3"], "is not a position near the Earth"),
    (["--reference", "1,2,3", "--reference-file", "f"], "not both"),
])
def test_bad_reference_is_one_line(tmp_path, capsys, args, expected):
    good = _write(tmp_path)
    assert main(["import", str(good), "-o", str(tmp_path / "o.h5"), *args]) == 2
    assert expected in capsys.readouterr().err


def test_hatanaka_missing_is_one_line(monkeypatch, tmp_path):
    import builtins

    real_import = builtins.__import__

    def no_hatanaka(name, *a, **k):
        if name == "hatanaka":
            raise ImportError(name)
        return real_import(name, *a, **k)

    monkeypatch.setattr(builtins, "__import__", no_hatanaka)
    with pytest.raises(InputError, match="install the 'hatanaka' package"):
        rinex_obs.read(DATA / "KMS300DNK_R_20221591000_01H_30S_MO.crx")


def test_navigation_of_another_day_is_one_line(tmp_path):
    kms3_nav = Path(__file__).parents[1] / "simkit" / "data" / "KMS300DNK_R_20221591000_01H_MN.rnx.gz"
    with pytest.raises(DataFileError, match=r"no broadcast record is valid during the observations \(2016-06-06 "
                                            r"10:59:43 to .*covers .*2022-06-08"):
        importer.import_rinex(_write(tmp_path), [kms3_nav])


def test_a_file_of_systems_simkit_does_not_know_is_one_line(tmp_path):
    header = HEADER[:4] + [_h("S    2 C1C L1C", "SYS / # / OBS TYPES")] + HEADER[6:]
    body = ["> 2016 06 06 11 00 00.0000000  0  1", "S20  21000000.123 7 110355000.456 7"]
    with pytest.raises(DataFileError, match="no observation of a signal simkit knows .* the file has S: C1C L1C"):
        importer.import_rinex(_write(tmp_path, header, body))


@pytest.mark.parametrize("line, what", [
    ("  2 R03  5 R04 x6", "frequency number 'x6' of R04"),
    ("  2 R03  5 R04 14", "frequency number '14' of R04"),
    ("  1 G03  5", "bad satellite 'G03'"),
])
def test_a_bad_glonass_slot_record_is_one_line(tmp_path, line, what):
    header = HEADER[:-1] + [_h(line, "GLONASS SLOT / FRQ #")] + HEADER[-1:]
    text = _error(_write(tmp_path, header=header))
    assert what in text and "GLONASS SLOT / FRQ #" in text and ".rnx:8:" in text


def test_glonass_slot_records_give_the_frequency_numbers(tmp_path):
    header = HEADER[:-1] + [_h(" 10 R03  5 R04  6 R05  1 R10 -7 R11  0 R12 -1 R13 -2 R20  2", "GLONASS SLOT / FRQ #"),
                            _h("    R21  4 R23  3", "GLONASS SLOT / FRQ #")] + HEADER[-1:]
    channels = rinex_obs.read(_write(tmp_path, header=header)).header.glonass_channels
    assert channels == {"R03": 5, "R04": 6, "R05": 1, "R10": -7, "R11": 0, "R12": -1, "R13": -2, "R20": 2,
                        "R21": 4, "R23": 3}
