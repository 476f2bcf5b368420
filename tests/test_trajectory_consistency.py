"""Inertial consistency of the truth: an independent ECEF strapdown integration of /truth/omega_ib_b and
/truth/f_ib_b from the initial truth state must reproduce /truth/pos_ecef, /truth/vel_enu and /truth/quat_nb."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import strapdown_reference as ref
from simkit import frames
from simkit.scenario import bundled_names, load
from simkit.trajectory import Trajectory


def _truth(name, overrides=()):
    sc = load(name, list(overrides))
    blocks = list(Trajectory(sc.trajectory, sc.duration_s).blocks())
    return sc, {k: np.concatenate([getattr(b, k) for b in blocks]) for k in blocks[0].arrays()}


def _strapdown_errors(truth, rate):
    lla = truth["pos_lla"]
    c_en = frames.ecef_to_enu_matrix(lla[:, 0], lla[:, 1])
    r_be = Rotation.from_matrix(np.transpose(c_en, (0, 2, 1))) * Rotation.from_quat(truth["quat_nb"])
    v_e = frames.enu_to_ecef_vec(truth["vel_enu"], lla[:, 0], lla[:, 1])
    q, r, v = ref.integrate(r_be[0].as_quat(), truth["pos_ecef"][0], v_e[0], truth["omega_ib_b"],
                            truth["f_ib_b"], 1.0 / rate)
    idx = slice(None)
    pos_err = np.linalg.norm(r - truth["pos_ecef"][idx], axis=1).max()
    vel_err = np.linalg.norm(v - v_e[idx], axis=1).max()
    att_err = np.degrees((Rotation.from_quat(q).inv() * r_be[idx]).magnitude().max()) * 3600
    return pos_err, vel_err, att_err


def test_high_dynamic_at_1khz_over_120s():
    sc, truth = _truth("high_dynamic", ["trajectory.rate_hz=1000.0", "scenario.duration_s=120.0"])
    g = np.linalg.norm(truth["f_ib_b"], axis=1) / 9.80665
    assert g.max() >= 5.0 and np.degrees(np.abs(truth["omega_ib_b"][:, 1]).max()) >= 200.0
    pos_err, vel_err, att_err = _strapdown_errors(truth, 1000.0)
    print(f"\nhigh_dynamic 1 kHz 120 s: position {pos_err * 100:.4f} cm, velocity {vel_err * 1e3:.4f} mm/s, "
          f"attitude {att_err:.5f} arcsec")
    assert pos_err < 0.05
    assert att_err < 1.0


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n == "xian_static_bds" else n
                                  for n in bundled_names()])   # 24 h at 10 Hz: 10 s and 0.3 GB
def test_every_bundled_scenario_at_its_own_rate(name):
    sc, truth = _truth(name)
    pos_err, vel_err, att_err = _strapdown_errors(truth, sc.trajectory.rate_hz)
    print(f"\n{name} ({sc.trajectory.rate_hz:g} Hz, {sc.duration_s:g} s): position {pos_err:.4g} m, "
          f"velocity {vel_err:.3g} m/s, attitude {att_err:.4g} arcsec")
    assert pos_err < 1.0
    assert att_err < 10.0


def test_truth_does_not_depend_on_the_sample_rate():
    """The truth does not depend on the sample grid: 100 Hz and 1 kHz agree at common instants (0.15 um, 0.03", 1.5e-6 m/s^2)."""
    _, a = _truth("high_dynamic", ["scenario.duration_s=150.0"])
    _, b = _truth("high_dynamic", ["scenario.duration_s=150.0", "trajectory.rate_hz=1000.0"])
    b = {k: v[::10] for k, v in b.items()}
    assert np.abs(a["pos_ecef"] - b["pos_ecef"]).max() < 1e-5
    att = (Rotation.from_quat(a["quat_nb"]).inv() * Rotation.from_quat(b["quat_nb"])).magnitude().max()
    assert np.degrees(att) * 3600 < 0.5
    assert np.abs(a["f_ib_b"] - b["f_ib_b"]).max() < 1e-5  # 1 ug
