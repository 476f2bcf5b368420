"""End to end: scenario -> HDF5 file; determinism, atomic writes, clear errors with exit code 2."""
import subprocess
import sys

import h5py
import numpy as np
import pytest

import simkit
from simkit.cli import main
from simkit.errors import DataFileError


def _arrays(path):
    out = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda n, o: out.__setitem__(n, o[...]) if isinstance(o, h5py.Dataset) else None)
    return out


def test_same_scenario_and_seed_give_identical_arrays(tmp_path):
    """Also when one run compresses on its own thread (as campaign runs do) and the other on a lane of workers."""
    a = simkit.run("quickstart", out=tmp_path / "a.h5", overrides=["scenario.duration_s=20"])
    b = simkit.run("quickstart", out=tmp_path / "b.h5", overrides=["scenario.duration_s=20"], threads=1)
    xa, xb = _arrays(a), _arrays(b)
    assert xa.keys() == xb.keys() and "truth/f_ib_b" in xa
    for k in xa:
        assert np.array_equal(xa[k], xb[k], equal_nan=xa[k].dtype.kind == "f"), k


def test_truth_and_imu_run_imports_no_scipy_spatial_numba_skyfield_or_pymap3d(tmp_path):
    """The start-up of a truth + IMU run (the CLI parser of every verb included) stays light: none of those
    modules (about 0.3 s of CPU together; pymap3d with dateutil ~10 ms) is needed without [gnss]."""
    from truth_imu_scenario import truth_imu_toml

    path = truth_imu_toml(tmp_path, 2.0)
    code = ("import sys\nfrom simkit.cli import main\n"
            f"assert main(['run', {str(path)!r}, '-o', {str(tmp_path / 'out.h5')!r}, '-q']) == 0\n"
            "print(sorted({m.split('.')[0] + ('.spatial' if m.startswith('scipy.spatial') else '') for m in sys.modules"
            " if m.startswith(('scipy.spatial', 'numba', 'skyfield', 'pymap3d', 'dateutil'))}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"
    with h5py.File(tmp_path / "out.h5", "r") as f:
        assert f["imu/gyro"].shape == (201, 3) and "imu/errors/gyro_bias" in f


def test_bad_thread_count_in_the_environment_is_one_clean_line(tmp_path):
    env = {**__import__("os").environ, "SIMKIT_NUM_THREADS": "two"}
    out = subprocess.run([sys.executable, "-m", "simkit", "run", "quickstart", "-o", str(tmp_path / "q.h5")],
                         env=env, capture_output=True, text=True)
    assert out.returncode == 2 and out.stderr.count("\n") == 1
    assert "$SIMKIT_NUM_THREADS" in out.stderr and "positive integer" in out.stderr
    assert list(tmp_path.iterdir()) == []


def test_file_layout_units_and_provenance(tmp_path):
    path = simkit.run("quickstart", out=tmp_path / "q.h5", seed=7, overrides=["scenario.duration_s=10"])
    with simkit.open(path) as ds:
        assert ds.attrs["schema_version"] == 1 and ds.attrs["seed"] == 7
        assert "name = \"quickstart\"" in ds.attrs["scenario_toml"]
        assert "--set scenario.duration_s=10" in ds.attrs["scenario_toml"]
        n = ds["truth/t"].shape[0]
        assert n == 1001 and ds.rate_hz("truth") == pytest.approx(100.0)
        for name, shape in [("pos_ecef", (n, 3)), ("pos_lla", (n, 3)), ("vel_enu", (n, 3)), ("quat_nb", (n, 4)),
                            ("euler", (n, 3)), ("omega_ib_b", (n, 3)), ("f_ib_b", (n, 3))]:
            assert ds[f"truth/{name}"].shape == shape
            assert ds[f"truth/{name}"].attrs["units"]
    with h5py.File(path, "r") as f:
        assert all(f[f"truth/{name}"].compression == "gzip" for name in ("pos_ecef", "f_ib_b"))


def test_stored_scenario_reproduces_the_file_bit_for_bit(tmp_path):
    """The effective scenario (overrides and --seed applied) is what the file keeps; running it again gives the
    same arrays."""
    a = simkit.run("quickstart", out=tmp_path / "a.h5", seed=11,
                   overrides=["scenario.duration_s=8", "gnss.elevation_mask_deg=15.0", "imu.preset='stim300'"])
    with simkit.open(a) as ds:
        text = ds.attrs["scenario_toml"]
    assert "seed = 11" in text and "elevation_mask_deg = 15.0" in text
    (tmp_path / "again.toml").write_text(text)
    b = simkit.run(tmp_path / "again.toml", out=tmp_path / "b.h5")
    xa, xb = _arrays(a), _arrays(b)
    assert xa.keys() == xb.keys()
    for k in xa:
        assert np.array_equal(xa[k], xb[k], equal_nan=xa[k].dtype.kind == "f"), k


def test_block_size_does_not_change_the_output(tmp_path):
    from simkit.pipeline import run

    a = run("quickstart", out=tmp_path / "a.h5", overrides=["scenario.duration_s=30"], block_samples=333)
    b = run("quickstart", out=tmp_path / "b.h5", overrides=["scenario.duration_s=30"])
    xa, xb = _arrays(a), _arrays(b)
    for k in xa:
        if k.startswith("truth/"):  # float rounding of block-wise sums (ECEF ulp ~1e-9 m)
            assert np.allclose(xa[k], xb[k], rtol=0, atol=1e-6), k


def test_interrupted_run_leaves_no_file(tmp_path, monkeypatch):
    from simkit import pipeline

    def boom(*a, **k):
        raise RuntimeError("killed")

    out = tmp_path / "x.h5"
    monkeypatch.setattr(pipeline.Writer, "append", boom)
    with pytest.raises(RuntimeError):
        pipeline.run("quickstart", out=out)
    assert not out.exists() and not list(tmp_path.iterdir())


@pytest.mark.slow
def test_killed_process_leaves_nothing_under_the_output_name(tmp_path):
    out = tmp_path / "big.h5"
    proc = subprocess.Popen([sys.executable, "-m", "simkit", "run", "xian_static_bds", "-q", "-o", str(out),
                             "--set", "trajectory.rate_hz=100.0"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    import time

    deadline = time.time() + 60
    while not any(p.name.startswith(".big.h5.tmp") for p in tmp_path.iterdir()) and time.time() < deadline:
        time.sleep(0.1)
    time.sleep(1.0)  # midway through writing
    proc.kill()
    proc.wait()
    assert proc.returncode != 0 and not out.exists()


@pytest.mark.parametrize("args,needle", [
    (["--set", "scenario.duration_s=-5"], "scenario.duration_s: must be > 0, got -5.0"),
    (["--set", "trajectory.segment[1].accel_m_per_s2=fast"], "trajectory.segment[1].accel_m_per_s2: expected a number"),
    (["--set", "trajectory.colour=1"], "trajectory.colour: unknown key"),
    (["--set", "trajectory.segment[9].kind=turn"], "trajectory.segment[9].kind: --set: segment has 4 entries, no index 9"),
])
def test_bad_input_is_one_line_and_exit_code_2(tmp_path, capsys, args, needle):
    out = tmp_path / "never.h5"
    code = main(["run", "quickstart", "-q", "-o", str(out)] + args)
    err = capsys.readouterr().err
    assert code == 2 and needle in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_malformed_toml_and_missing_keys(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("[scenario\nname = 1\n")
    assert main(["run", str(bad), "-q"]) == 2
    assert "bad.toml: not valid TOML" in capsys.readouterr().err
    bad.write_text('[scenario]\nname = "x"\nstart = "2026-01-01T00:00:00Z"\n[trajectory]\nrate_hz = 10.0\n')
    assert main(["run", str(bad), "-q"]) == 2
    err = capsys.readouterr().err
    assert "bad.toml: scenario.duration_s: missing required key" in err


def test_open_rejects_foreign_files(tmp_path):
    plain = tmp_path / "plain.h5"
    with h5py.File(plain, "w") as f:
        f["x"] = 1
    with pytest.raises(DataFileError, match="not a simkit file"):
        simkit.open(plain)
    (tmp_path / "text.h5").write_text("hello")
    with pytest.raises(DataFileError, match="not an HDF5 file"):
        simkit.open(tmp_path / "text.h5")
    with h5py.File(tmp_path / "v9.h5", "w") as f:
        f.attrs["schema_version"] = 9
    with pytest.raises(DataFileError, match="schema version 9"):
        simkit.open(tmp_path / "v9.h5")


def test_inspect_prints_groups_rates_and_units(tmp_path, capsys):
    path = simkit.run("quickstart", out=tmp_path / "q.h5", overrides=["scenario.duration_s=5"])
    assert main(["inspect", str(path)]) == 0
    out = capsys.readouterr().out
    assert "scenario: quickstart" in out and "/truth: 100 Hz, 5 s, 501 samples" in out
    assert "/truth/f_ib_b" in out and "m/s^2" in out


def test_help_everywhere():
    for cmd in ([], ["run"], ["inspect"]):
        r = subprocess.run([sys.executable, "-m", "simkit", *cmd, "--help"], capture_output=True, text=True)
        assert r.returncode == 0 and "usage: simkit" in r.stdout


def test_compressed_chunks_decode_through_hdf5s_own_filters(tmp_path):
    """Chunks are deflated by simkit (ISA-L) and written directly; the HDF5 library must decode them exactly."""
    from simkit.scenario import load
    from simkit.trajectory import Trajectory

    over = ["scenario.duration_s=1400"]  # 140,001 samples: two full chunks and a padded partial one
    path = simkit.run("quickstart", out=tmp_path / "q.h5", overrides=over)
    sc = load("quickstart", over)
    blocks = list(Trajectory(sc.trajectory, sc.duration_s).blocks())
    with h5py.File(path, "r") as f:
        ds = f["truth/f_ib_b"]
        assert ds.compression == "gzip" and ds.shuffle and ds.chunks[0] < ds.shape[0] < 3 * ds.chunks[0]
        assert np.array_equal(ds[...], np.concatenate([b.f_ib_b for b in blocks]))
        assert np.array_equal(f["truth/t"][...], np.concatenate([b.t for b in blocks]))
