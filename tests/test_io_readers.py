"""The typed readers of simkit.io (read_truth, read_imu, read_gnss) against the file's own datasets read with h5py,
their errors, and the rule they serve: the consumers above the file spell no dataset path."""
import ast
from pathlib import Path

import h5py
import numpy as np
import pytest

import simkit
from simkit.errors import DataFileError
from simkit.io import n_antennas, n_samples, read_gnss, read_imu, read_truth

PKG = Path(__file__).resolve().parents[1] / "simkit"


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    return simkit.run("quickstart", out=tmp_path_factory.mktemp("readers") / "q.h5",
                      overrides=["scenario.duration_s=4"])


def test_read_truth_is_the_files_truth_whole_in_a_span_and_at_times(small):
    with h5py.File(small) as f, simkit.open(small) as ds:
        t, pos, euler = f["truth/t"][:], f["truth/pos_ecef"][:], f["truth/euler"][:]
        whole = read_truth(ds)
        assert np.array_equal(whole.t, t) and np.array_equal(whole.pos_ecef, pos)
        assert np.array_equal(whole.lever_arm_b, f["gnss/antennas/lever_arm_b"][:]) and whole.euler is None
        part = read_truth(ds, span=(1.005, 2.0))        # the samples that bracket the span, no more
        assert part.t[0] == t[100] and part.t[-1] == t[200]
        assert np.array_equal(part.vel_enu, f["truth/vel_enu"][100:201])
        want = np.array([0.0, 0.004, 0.01, 3.999, 99.0])   # first sample at or after, the last past the end
        at = read_truth(ds, t=want, fields=("euler",), required=("euler",))
        k = np.array([0, 1, 1, 400, 400])
        assert np.array_equal(at.t, t[k]) and np.array_equal(at.euler, euler[k])
        strided = read_truth(ds, fields=("pos_lla",), required=(), epochs=slice(None, None, 7))
        assert np.array_equal(strided.pos_lla, f["truth/pos_lla"][::7]) and n_samples(ds, "truth") == t.size


def test_read_imu_and_read_gnss_select_what_is_asked(small):
    with h5py.File(small) as f, simkit.open(small) as ds:
        imu = read_imu(ds, fields=("gyro", "dtheta"), epochs=slice(5, 50), errors=("gyro_bias",))
        assert np.array_equal(imu.gyro, f["imu/gyro"][5:50]) and imu.dtheta is None and imu.accel is None
        assert np.array_equal(imu.errors["gyro_bias"], f["imu/errors/gyro_bias"][5:50])
        sig = f["gnss/signals"].asstr()[-1]
        g = read_gnss(ds, signals=[sig], antennas=1, epochs=slice(1, None, 2), obs=("carrier",),
                      truth=("elevation", f"{sig}/noise_code", "no_such_term", "satellite_clock_error",
                             "orbit_error_rac"))
        # per-satellite truth (M, S, ...) keeps every satellite: antennas=1 is not its column 1
        for name in ("satellite_clock_error", "orbit_error_rac"):
            assert np.array_equal(g.truth[name], f[f"gnss/truth/{name}"][1::2], equal_nan=True), name
        assert g.signals == (sig,) and n_antennas(ds) == f["gnss/antennas/lever_arm_b"].shape[0]
        assert np.array_equal(g.obs["carrier"][sig], f[f"gnss/obs/{sig}/carrier"][1::2, 1], equal_nan=True)
        assert np.array_equal(g.truth["elevation"], f["gnss/truth/elevation"][1::2, 1], equal_nan=True)
        assert np.array_equal(g.truth[f"{sig}/noise_code"], f[f"gnss/truth/{sig}/noise_code"][1::2, 1],
                              equal_nan=True)
        assert "no_such_term" not in g.truth and np.array_equal(g.t, f["gnss/t"][1::2])
        j = list(f["gnss/signals"].asstr()[:]).index(sig)
        assert g.wavelength_m[0] == f["gnss/wavelength_m"][j]
        assert np.array_equal(g.group_delay[:, 0], f["gnss/group_delay"][:, j], equal_nan=True)
        assert np.array_equal(g.sat_pos_ecef, f["gnss/sat_pos_ecef"][1::2], equal_nan=True)
        assert np.array_equal(g.lever_arm_b, f["gnss/antennas/lever_arm_b"][1])


def test_reader_errors_name_the_file_and_the_dataset(small, tmp_path):
    with simkit.open(small) as ds:
        with pytest.raises(DataFileError, match=r"q\.h5: /gnss/signals: no signal 'X9', the file has"):
            read_gnss(ds, signals=["X9"])
    text = (PKG / "scenarios/quickstart.toml").read_text()
    (tmp_path / "bare.toml").write_text(text[:text.index("\n[gnss")])       # its [gnss] sections come last
    bare = simkit.run(tmp_path / "bare.toml", out=tmp_path / "bare.h5", overrides=["scenario.duration_s=1"])
    with simkit.open(bare) as ds:
        with pytest.raises(DataFileError, match=r"bare\.h5: no /gnss/t dataset"):
            read_gnss(ds)
        assert read_truth(ds).lever_arm_b is None and n_antennas(ds) == 0
        with pytest.raises(DataFileError, match=r"bare\.h5: no /truth/no_such dataset"):
            read_truth(ds, fields=("f_ib_b",), required=("no_such",))


# the consumers that read the file through the typed readers (simkit/referee/regress.py names its regression
# quantities "gnss/L1C/cn0.mean", ...: names of numbers, not dataset paths, so it is not listed)
READERS = [*sorted((PKG / "estimators").glob("*.py")), PKG / "attitude/reading.py", PKG / "attitude/velocity.py",
           *sorted(p for p in (PKG / "referee").glob("*.py") if p.name != "regress.py"),
           *sorted((PKG / "campaign").glob("*.py")), PKG / "validation/geometry.py", PKG / "plots/file_figures.py"]


def _dataset_paths(path: Path) -> list[str]:
    """String constants (and f-string heads) of ``path`` that start with a /truth, /imu or /gnss dataset path."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            text = node.value
        elif isinstance(node, ast.JoinedStr) and node.values and isinstance(node.values[0], ast.Constant):
            text = str(node.values[0].value)
        else:
            continue
        if text.startswith(("truth/", "imu/", "gnss/")):
            found.append(f"{path.relative_to(PKG)}:{node.lineno}: {text!r}")
    return found


def test_the_consumers_spell_no_dataset_path():
    found = [hit for path in READERS for hit in _dataset_paths(path)]
    assert not found, "read these through simkit.io's typed readers:\n" + "\n".join(found)
