"""Single-point positioning against the simulator's truth: with the ionosphere, multipath and noise switched off
the observation model is exact (geometric range with light time and Earth rotation, clocks, group delays,
Saastamoinen troposphere), so the fix must reproduce the true antenna position and velocity; with the ionosphere
on, the broadcast Klobuchar correction from /gnss/iono_alpha, iono_beta is exact too (the simulated ionosphere
is that model, checked here against the file's own /gnss/truth/<signal>/ionosphere); without the correction the
fix is biased by the single-frequency ionosphere (bounded by its true size)."""
import shutil

import h5py
import numpy as np
import pytest

import simkit
from simkit.estimators import spp
from simkit.gnss.spp import SppInputError
from simkit.estimators.registry import DEFAULTS, spp_fixes
from simkit.frames import ecef_to_enu_vec, ecef_to_lla


def _truth(ds, a=0):
    pos = ds["gnss/truth/antenna_pos_ecef"][:, a]
    lla = ecef_to_lla(pos)
    return pos, lla, ecef_to_enu_vec(ds["gnss/truth/antenna_vel_ecef"][:, a], lla[:, 0], lla[:, 1])


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("spp")
    quiet = ["scenario.duration_s=20", "imu.preset=ideal", "gnss.errors.multipath=false", "gnss.errors.noise=false",
             "gnss.truth_errors.model='none'"]  # the receiver's models are the truth: SPP closes at mm
    clean = simkit.run("quickstart", out=d / "clean.h5", overrides=quiet + ["gnss.errors.ionosphere=false"])
    full = simkit.run("quickstart", out=d / "full.h5", overrides=["scenario.duration_s=20", "imu.preset=ideal"])
    iono = simkit.run("quickstart", out=d / "iono.h5", overrides=quiet)
    return clean, full, iono


def _without_iono_datasets(src, dst):
    """A copy of ``src`` as simkit wrote it before /gnss/iono_* existed."""
    shutil.copyfile(src, dst)
    with h5py.File(dst, "a") as f:
        for name in ("iono_systems", "iono_alpha", "iono_beta"):
            del f["gnss"][name]
    return dst


def test_error_free_observations_give_the_true_antenna_state(files):
    with simkit.open(files[0]) as ds:
        fx = spp_fixes(ds, {**DEFAULTS["spp"], "ionosphere": "none"})  # no ionosphere was simulated
        pos, lla, vel = _truth(ds)
        clock = ds["gnss/truth/receiver_clock"][:, 0]
    dp = ecef_to_enu_vec(fx.pos_ecef - pos, lla[:, 0], lla[:, 1])
    # measured: 0.14 mm, 0.44 mm/s (central-difference satellite velocities), clock 0.04 mm
    assert np.abs(dp).max() < 1e-3
    assert np.abs(fx.vel_enu - vel).max() < 2e-3
    assert np.abs(fx.clock[:, fx.systems.index("G")] - clock).max() < 1e-3


def test_broadcast_correction_removes_the_simulated_ionosphere_exactly(files):
    with simkit.open(files[2]) as ds:
        fx = spp_fixes(ds, dict(DEFAULTS["spp"]))
        raw = spp_fixes(ds, {**DEFAULTS["spp"], "ionosphere": "none"})
        pos, lla, vel = _truth(ds)
        iono = np.nanmax(ds["gnss/truth/L1C/ionosphere"][:, 0])
    dp = ecef_to_enu_vec(fx.pos_ecef - pos, lla[:, 0], lla[:, 1])
    dp_raw = ecef_to_enu_vec(raw.pos_ecef - pos, lla[:, 0], lla[:, 1])
    assert fx.ionosphere.startswith("broadcast Klobuchar (C, G)") and raw.ionosphere.startswith("none")
    # measured: 0.17 mm, 0.38 mm/s (0.14 mm without ionosphere: the correction is the simulated delay)
    assert iono > 1.0 and np.abs(dp).max() < 1e-3
    assert np.abs(dp_raw[:, 2]).max() > 1.0
    assert np.abs(fx.vel_enu - vel).max() < 5e-3  # the ionosphere's rate (mm/s) stays in the Doppler velocity


def test_a_file_without_broadcast_coefficients_is_solved_uncorrected_and_says_so(files, tmp_path):
    from simkit.estimators.registry import SOLVERS

    old = _without_iono_datasets(files[2], tmp_path / "old.h5")
    with simkit.open(old) as ds, simkit.open(files[2]) as new:
        sol = SOLVERS["spp"](ds, {})
        raw = spp_fixes(new, {**DEFAULTS["spp"], "ionosphere": "none"})
    assert "has no /gnss/iono_alpha" in sol.config["ionosphere_correction"]
    np.testing.assert_array_equal(sol.pos_ecef, raw.pos_ecef)


def test_with_every_error_the_bias_is_within_the_ionosphere(files):
    with simkit.open(files[1]) as ds:
        fx = spp_fixes(ds, {**DEFAULTS["spp"], "ionosphere": "none"})
        pos, lla, vel = _truth(ds)
        iono = np.nanmax(ds["gnss/truth/L1C/ionosphere"][:, 0])
    dp = ecef_to_enu_vec(fx.pos_ecef - pos, lla[:, 0], lla[:, 1])
    horizontal = np.hypot(dp[:, 0], dp[:, 1])
    assert np.all(np.isfinite(dp)) and fx.n_sats.min() >= 5
    assert horizontal.max() < iono and np.abs(dp[:, 2]).max() < 3 * iono
    assert np.abs(fx.vel_enu - vel).max() < 0.2  # Doppler noise and the unmodelled ionosphere/troposphere rates


def test_too_few_satellites_give_nan_not_a_fix():
    m, s = 3, 3
    out = spp(np.arange(m, dtype=float), np.full((m, s), 2.2e7), np.zeros((m, s)), np.full(s, 0.19),
              np.tile([[2.6e7, 0, 0], [0, 2.6e7, 0], [0, 0, 2.6e7]], (m, 1, 1)), np.zeros((m, s)),
              np.array(["G"] * s))
    assert np.isnan(out.pos_ecef).all() and (out.n_sats == 0).all()


def test_shape_errors_name_the_arrays():
    with pytest.raises(SppInputError, match="sat_pos_ecef"):
        spp(np.arange(2.0), np.zeros((2, 4)), np.zeros((2, 4)), np.ones(4), np.zeros((2, 3, 3)),
            np.zeros((2, 4)), np.array(["G"] * 4))
