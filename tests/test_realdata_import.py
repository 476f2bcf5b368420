"""``simkit import`` of real receiver files, and the consumers (solve spp, score, plot) on them.

Authorities: RTKLIB 2.4.3 (pyrtklib postpos, single-point mode) on the same epochs of the same files, and the
station's own header position.
"""
from __future__ import annotations

import contextlib
import json

import numpy as np
import pytest

import simkit
from realdata_helpers import (BERLIN_NAV, BERLIN_OBS, CN00_NAV, CN00_OBS, KMS3_HEADER_POS, KMS3_NAV, KMS3_OBS, OBS,
                              rinex4_nav_as_rinex3, rtklib_spp)
from simkit.cli import main
from simkit.gnss import rinex_obs
from simkit.io import read_gnss


def _import(tmp_path, obs, nav=(), name="real.h5", extra=()):
    out = tmp_path / name
    args = ["import", str(obs), "-o", str(out), "-q", *extra]
    for n in nav:
        args += ["--nav", str(n)]
    assert main(args) == 0
    return out


@pytest.fixture(scope="module")
def kms3(tmp_path_factory):
    return _import(tmp_path_factory.mktemp("kms3"), KMS3_OBS, [KMS3_NAV])


def test_kms3_file_has_the_simulated_layout_without_truth(kms3):
    with simkit.open(kms3) as ds:
        assert "truth/t" not in ds
        sigs = [str(s) for s in ds["gnss/signals"][:]]
        assert sigs == ["L1C", "L2W", "L5Q", "B1I", "B3I", "B1C", "B2a", "E1C", "E5aQ", "E5bQ", "E6C", "G1C", "G2C",
                        "J1C", "J2L", "J5Q"]
        np.testing.assert_array_equal(ds["reference/pos_ecef"][:], KMS3_HEADER_POS)
        assert "RINEX header" in ds.group_attrs("reference")["source"]
        m, s = ds["gnss/t"].shape[0], ds["gnss/sat_id"].shape[0]
        assert m == 19 and ds["gnss/sat_pos_ecef"].shape == (m, s, 3)
        assert ds["gnss/obs/L1C/code"].shape == (m, 1, s)
        assert np.isnan(ds["gnss/obs/L1C/doppler"][:]).all()       # the file holds no Doppler
        report = json.loads(ds.attrs["import_report"])
        imported_from = json.loads(ds.attrs["imported_from"])
    assert imported_from["rinex_version"] == 4.0
    parsed = rinex_obs.read(KMS3_OBS)
    sbas = parsed.systems["S"]
    assert report["skipped_systems"] == {"S": {"satellites": len(sbas.sats),
                                               "observations": int(np.isfinite(sbas.values).sum())}}
    gps = parsed.systems["G"]
    assert report["skipped_codes"]["G C1W"] == int(np.isfinite(gps.values[..., gps.types.index("C1W")]).sum())
    assert report["observations"]["L1C"]["code"] == int(np.isfinite(gps.values[..., gps.types.index("C1C")]).sum())


def test_glonass_carriers_take_each_satellites_frequency_number(kms3):
    """KMS3's header lists the GLONASS frequency numbers ('GLONASS SLOT / FRQ #'): G1 = 1602 + 0.5625 k MHz and
    G2 = 1246 + 0.4375 k MHz per satellite (ICD GLONASS 5.1), the CDMA signals their own frequency."""
    with simkit.open(kms3) as ds:
        sats = [str(s) for s in ds["gnss/sat_id"][:]]
        sigs = [str(s) for s in ds["gnss/signals"][:]]
        freq = ds["gnss/sat_frequency_hz"][:]
        nominal = ds["gnss/frequency_hz"][:]
        g = read_gnss(ds, antennas=0, satellites=False)
    channels = rinex_obs.read(KMS3_OBS).header.glonass_channels
    assert channels["R10"] == -7 and channels["R03"] == 5 and len(channels) == 10
    g1, g2 = sigs.index("G1C"), sigs.index("G2C")
    for sat, k in channels.items():
        if sat in sats:
            i = sats.index(sat)
            assert freq[i, g1] == 1602e6 + 0.5625e6 * k and freq[i, g2] == 1246e6 + 0.4375e6 * k
    cdma = [j for j, n in enumerate(sigs) if n not in ("G1C", "G2C")]
    np.testing.assert_array_equal(freq[:, cdma], np.broadcast_to(nominal[cdma], (len(sats), len(cdma))))
    np.testing.assert_allclose(g.sat_wavelength_m, 299792458.0 / freq)


def test_satellites_sit_where_the_pseudoranges_say(kms3):
    """At each epoch, code + c dT - |r_sat - r_ref| - Sagnac is one receiver clock for all GPS satellites above
    10 deg, up to the atmosphere, group delay and noise (< 25 m spread): orbits and clocks at the emission time
    (an error of 1 ms in it moves a satellite by ~3 m along its orbit, and its range by up to ~1 m)."""
    import pymap3d

    with simkit.open(kms3) as ds:
        sats = [str(x) for x in ds["gnss/sat_id"][:]]
        code = ds["gnss/obs/L1C/code"][:, 0]
        pos, clk = ds["gnss/sat_pos_ecef"][:], ds["gnss/sat_clock"][:]
    lat, lon, h = pymap3d.ecef2geodetic(*KMS3_HEADER_POS)
    el = pymap3d.ecef2aer(pos[..., 0], pos[..., 1], pos[..., 2], lat, lon, h)[1]
    gps = np.array([x[0] == "G" for x in sats])[None, :] & (el > 10.0)
    rho = np.linalg.norm(pos - KMS3_HEADER_POS, axis=-1)
    sagnac = 7.2921151467e-5 * (pos[..., 0] * KMS3_HEADER_POS[1] - pos[..., 1] * KMS3_HEADER_POS[0]) / 299792458.0
    clock = np.where(gps, code + 299792458.0 * clk - rho - sagnac, np.nan)
    spread = np.nanmax(clock, axis=1) - np.nanmin(clock, axis=1)
    assert np.isfinite(clock).sum() > 100 and spread.max() < 25.0


@pytest.mark.parametrize("name", sorted(p.name for p in OBS.iterdir()))
def test_every_file_imports_without_navigation(tmp_path, name):
    out = _import(tmp_path, OBS / name)
    with simkit.open(out) as ds:
        report = json.loads(ds.attrs["import_report"])
        assert np.isnan(ds["gnss/sat_pos_ecef"][:]).all()
        assert report["navigation"].startswith("none")
        assert sum(v["code"] for v in report["observations"].values()) > 0


def test_berlin_rinex2_with_its_navigation_has_orbits_and_no_reference(tmp_path):
    out = _import(tmp_path, BERLIN_OBS, [BERLIN_NAV])
    with simkit.open(out) as ds:
        assert "reference/pos_ecef" not in ds                      # no APPROX POSITION in the header
        code = ds["gnss/obs/L1C/code"][:, 0]
        pos = ds["gnss/sat_pos_ecef"][:]
        assert np.isfinite(pos[np.isfinite(code)]).all()
        assert np.isfinite(ds["gnss/obs/L1C/doppler"][:]).any() and np.isfinite(ds["gnss/obs/L1C/cn0"][:]).any()
    assert main(["score", str(out), str(out)]) == 2                # no /truth and no /reference: one clear line


def test_the_given_reference_replaces_the_header(tmp_path):
    ref = tmp_path / "ref.txt"
    ref.write_text("# KMS3, moved 1 m up\n3516213.4380 781859.8595 5246038.9660\n")
    out = _import(tmp_path, KMS3_OBS, [KMS3_NAV], extra=("--reference-file", str(ref)))
    with simkit.open(out) as ds:
        assert ds["reference/pos_ecef"][2] == 5246038.9660
        assert "user" in ds.group_attrs("reference")["source"]


def _solve(path, iono, systems=""):
    assert main(["solve", str(path), "--filter", "spp", "--name", f"spp_{iono.replace('-', '_')}", "-q",
                 "--set", f'estimator.ionosphere="{iono}"', "--set", f'estimator.systems="{systems}"']) == 0
    with simkit.open(path) as ds:
        name = f"spp_{iono.replace('-', '_')}"
        return ds["gnss/t"][:] + ds.attrs["start_gps_sow"], ds[f"solutions/{name}/pos_ecef"][:]


def test_spp_on_kms3_agrees_with_rtklib_on_the_same_epochs(kms3, tmp_path):
    """Broadcast ephemerides and Klobuchar, Saastamoinen, 10 deg mask, GPS+BDS: simkit's and RTKLIB's SPP differ
    only by their weights (simkit sin^2(el); RTKLIB its error model) and code choice: under 1 m at every epoch,
    and both are a broadcast SPP's 1-3 m from the header position with RMS within 30 % of each other."""
    import pyrtklib as rtk

    t, ours = _solve(kms3, "broadcast", "GC")
    obs = tmp_path / "kms3_as_305.rnx"
    text = rinex_obs.decompress(KMS3_OBS).decode("latin-1")
    obs.write_text("     3.05" + text[9:], encoding="latin-1")   # RTKLIB 2.4.3 reads no RINEX 4 observations
    nav = rinex4_nav_as_rinex3(KMS3_NAV, tmp_path / "kms3_nav.rnx")
    t_rtk, theirs = rtklib_spp(obs, nav, tmp_path / "rtk.pos", rtk.SYS_GPS | rtk.SYS_CMP, rtk.IONOOPT_BRDC)
    np.testing.assert_allclose(t_rtk, t, atol=1e-3)
    diff = np.linalg.norm(ours - theirs, axis=1)
    rms = [np.sqrt(np.mean(np.sum((x - KMS3_HEADER_POS) ** 2, axis=1))) for x in (ours, theirs)]
    print(f"\nKMS3 SPP 3-D RMS: simkit {rms[0]:.2f} m, RTKLIB {rms[1]:.2f} m; simkit - RTKLIB: RMS "
          f"{np.sqrt(np.mean(diff ** 2)):.2f} m, max {diff.max():.2f} m")
    assert diff.max() < 1.0
    assert all(0.5 < r < 3.0 for r in rms) and abs(rms[0] / rms[1] - 1.0) < 0.3


def test_spp_on_cn00_with_a_rinex2_navigation_file_agrees_with_rtklib(tmp_path):
    """A RINEX 2.11 observation file (GPS, 24 h at 30 s) with its RINEX 2.11 broadcast file: simkit's SPP (broadcast
    Klobuchar, Saastamoinen, 10 deg mask) and RTKLIB's on the same 2880 epochs are both a broadcast SPP's 1-3 m
    (3-D RMS: 2.30 and 2.35 m) from the station's header position, within 30 % of each other. With GPS alone (8-12
    satellites) their weights (simkit sin^2(el), RTKLIB its error model with the Klobuchar variance) move the
    solutions apart more than on KMS3's GPS+BDS sky: 0.9 m RMS, every epoch within 3.5 m."""
    import pyrtklib as rtk

    real = _import(tmp_path, CN00_OBS, [CN00_NAV])
    t, ours = _solve(real, "broadcast", "G")
    with simkit.open(real) as ds:
        ref = ds["reference/pos_ecef"][:]
    t_rtk, theirs = rtklib_spp(CN00_OBS, CN00_NAV, tmp_path / "rtk.pos", rtk.SYS_GPS, rtk.IONOOPT_BRDC)
    assert t.size == 2880
    np.testing.assert_allclose(t_rtk, t, atol=1e-3)
    diff = np.linalg.norm(ours - theirs, axis=1)
    rms = [np.sqrt(np.mean(np.sum((x - ref) ** 2, axis=1))) for x in (ours, theirs)]
    print(f"\nCN00 SPP 3-D RMS: simkit {rms[0]:.2f} m, RTKLIB {rms[1]:.2f} m; simkit - RTKLIB: RMS "
          f"{np.sqrt(np.mean(diff ** 2)):.2f} m, max {diff.max():.2f} m")
    assert np.sqrt(np.mean(diff ** 2)) < 1.5 and diff.max() < 3.5
    assert all(0.5 < r < 3.0 for r in rms) and abs(rms[0] / rms[1] - 1.0) < 0.3


def test_ionosphere_free_spp_removes_the_klobuchar_residual(kms3):
    _, brdc = _solve(kms3, "broadcast")
    _, free = _solve(kms3, "iono-free")
    rms = [np.sqrt(np.mean(np.sum((x - KMS3_HEADER_POS) ** 2, axis=1))) for x in (brdc, free)]
    assert rms[1] < 1.5 and rms[1] < rms[0]


def test_score_uses_the_reference_and_says_so(kms3, tmp_path, capsys):
    _solve(kms3, "broadcast")
    out = tmp_path / "score.json"
    assert main(["score", str(kms3), str(kms3), "--solution", "spp_broadcast", "--json", str(out)]) == 0
    assert "/reference (static: RINEX header" in capsys.readouterr().out
    summary = json.loads(out.read_text())
    assert 0.5 < summary["statistics"]["position_3d"]["rms"] < 3.0
    assert summary["meta"]["truth"].startswith("/reference")


def test_plot_runs_on_a_real_file(kms3, tmp_path):
    pytest.importorskip("matplotlib")
    _solve(kms3, "broadcast")
    assert main(["plot", str(kms3), "--out", str(tmp_path / "plots")]) == 0
    assert list((tmp_path / "plots").rglob("*.png"))


def test_the_glonass_frequency_note_names_glonass_satellites_only(tmp_path, kms3):
    """A satellite of another system has no GLONASS frequency number to miss: the import note lists only the
    GLONASS satellites without one (solo0150 without navigation: its header gives none), and none for KMS3, whose
    header gives every observed GLONASS satellite's number."""
    def note(path):
        with simkit.open(path) as ds:
            notes = json.loads(ds.attrs["import_report"])["notes"]
        return [n for n in notes if "GLONASS frequency number" in n]

    assert note(kms3) == []
    solo = _import(tmp_path, OBS / "solo0150.16o")
    [line] = note(solo)
    listed = line.split(" for ", 1)[1].split(":")[0].split()
    glonass = [s for s in rinex_obs.read(OBS / "solo0150.16o").systems["R"].sats]
    assert listed and sorted(listed) == sorted(glonass)
    with simkit.open(solo) as ds:                       # and those satellites' FDMA frequencies are unknown
        sats = [str(x) for x in ds["gnss/sat_id"][:]]
        assert np.isnan(ds["gnss/sat_frequency_hz"][:][[sats.index(x) for x in listed]]).any(axis=1).all()


def test_nav_takes_a_bundled_file_name_from_any_folder(tmp_path, kms3):
    """`--nav NAME` of a navigation file shipped in simkit/data works from any folder, as `simkit sky NAME` does
    (the commands of docs/real_data.md), and gives the file the explicit path gives."""
    out = tmp_path / "named.h5"
    with contextlib.chdir(tmp_path):
        assert main(["import", str(KMS3_OBS), "--nav", KMS3_NAV.name, "-o", str(out), "-q"]) == 0
    with simkit.open(out) as a, simkit.open(kms3) as b:
        np.testing.assert_array_equal(a["gnss/sat_pos_ecef"][:], b["gnss/sat_pos_ecef"][:])


def test_plot_of_a_real_file_without_reference_says_why_and_leaves_nothing(tmp_path):
    """Berlin has no reference position: its SPP cannot be scored, so `simkit plot` names the solutions it skips
    and why, says no figure was drawn (exit 1), and leaves no empty folder (it was exit 2 on the first solution,
    or an empty folder and exit 0)."""
    from cli_errors import run_cli

    out = _import(tmp_path, BERLIN_OBS, [BERLIN_NAV])
    assert main(["solve", str(out), "--filter", "spp", "-q", "--set", 'estimator.systems="G"']) == 0
    proc = run_cli(["plot", out.name, "--out", "figs"], tmp_path)
    lines = [ln for ln in proc.stderr.replace("\r", "\n").splitlines() if ln.startswith(("plot: skipped", "simkit"))]
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    assert lines[0].startswith("plot: skipped the figures of /solutions/spp: ") and "no /truth" in lines[0]
    assert lines[1].startswith(f"simkit plot: error: {out.name}: no figure drawn") and len(lines) == 2
    assert not (tmp_path / "figs").exists() and not list(tmp_path.glob(".figs*"))


@pytest.mark.parametrize("solver", ["attitude", "attitude_c", "tdcp"])
def test_an_attitude_solver_on_a_real_file_names_its_one_antenna(kms3, solver, capsys):
    """An imported file has one antenna: the carrier-phase solvers say so (it was "gnss/obs/L1C/ambiguity: no
    such dataset"), one line, exit 1, nothing stored."""
    assert main(["solve", str(kms3), "--filter", solver, "-q"]) == 1
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert err == [f"simkit solve: {solver}: failed: gnss/antennas/lever_arm_b: 1 antenna(s); expected at least 2 "
                   "(one baseline)"]
    with simkit.open(kms3) as ds:
        assert f"solutions/{solver}/t" not in ds
