"""The real ionosphere against Klobuchar (simkit/realdata/ionosphere.py): the carrier-levelled geometry-free code
of synthetic dual-frequency observations with a known ionosphere, receiver bias, group delays and ambiguities
gives back the ratio to the model, the bias and the residual fraction in closed form."""
from __future__ import annotations

import numpy as np
import pytest

from simkit import frames
from simkit.gnss import atmosphere
from simkit.gnss import signals as sigmod
from simkit.realdata import ionosphere, twin

L1, L2 = sigmod.get("L1C"), sigmod.get("L2W")
REF = np.array([3516213.438, 781859.8595, 5246037.966])          # KMS3
ALPHA = np.array([1.02445483e-08, 2.23517418e-08, -5.96046448e-08, -1.19209290e-07])
BETA = np.array([96256.0, 131072.0, -65536.0, -589824.0])
START = (2213, 295200.0 + 36000.0)


def _real(ratio_of_sat, bias_m=-1.3, seed=0):
    """Six GPS satellites at fixed directions for 21 epochs of 30 s; I1 = ratio * Klobuchar on L1."""
    rng = np.random.default_rng(seed)
    t = np.arange(21) * 30.0
    el = np.radians([12.0, 25.0, 38.0, 50.0, 65.0, 80.0])
    az = np.radians([30.0, 100.0, 170.0, 220.0, 290.0, 340.0])
    lla = frames.ecef_to_lla(REF[None])[0]
    enu = np.column_stack([np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)])
    r_ne = frames.ecef_to_enu_matrix(lla[0], lla[1])
    sat = REF + 2.2e7 * enu @ r_ne                                 # ENU -> ECEF (rows: r_ne^T applied)
    sat_pos = np.broadcast_to(sat, (t.size, 6, 3)).copy()
    sow = START[1] + t
    klob = atmosphere.broadcast_ionosphere("G", ALPHA, BETA, lla[0], lla[1], az, el, sow[:, None])
    iono1 = klob * np.asarray(ratio_of_sat)[None, :]
    gamma = (L1.freq_hz / L2.freq_hz) ** 2
    rho = 2.2e7 + 100.0 * t[:, None] + np.zeros((1, 6))
    gd = np.column_stack([rng.normal(0, 3, 6), rng.normal(0, 5, 6)])    # m, per satellite
    obs = {k: {} for k in twin.KINDS}
    obs["code"]["L1C"] = rho + gd[:, 0] + iono1
    obs["code"]["L2W"] = rho + gd[:, 1] + gamma * iono1 + bias_m
    obs["carrier"]["L1C"] = (rho - iono1) / L1.wavelength_m + rng.integers(-10**6, 10**6, 6)
    obs["carrier"]["L2W"] = (rho - gamma * iono1) / L2.wavelength_m + rng.integers(-10**6, 10**6, 6)
    for s in ("L1C", "L2W"):
        obs["lli"][s] = np.zeros((t.size, 6), np.uint8)
    return {"t": t, "sat_id": [f"G{k + 1:02d}" for k in range(6)], "signals": ["L1C", "L2W"],
            "freq": np.array([L1.freq_hz, L2.freq_hz]), "sat_pos": sat_pos, "obs": obs, "start": START,
            "group_delay": gd, "iono": {"G": (ALPHA, BETA)}}


@pytest.mark.parametrize("ratio", [1.0, 0.7, 1.4])
def test_a_scaled_klobuchar_is_its_ratio_with_the_receiver_bias_recovered(ratio):
    real = _real(np.full(6, ratio))
    r = ionosphere.klobuchar_ratio(real, REF, real["group_delay"], real["iono"])["G"]
    assert r["signals"] == ["L1C", "L2W"] and r["satellites"] == 6
    assert r["mean_ratio"] == pytest.approx(ratio, abs=1e-6)
    assert r["receiver_bias_m"] == pytest.approx(-1.3, abs=1e-5)
    assert r["residual_fraction"] == pytest.approx(abs(ratio - 1.0), abs=1e-6)


def test_a_satellite_off_the_model_shows_in_its_own_ratio_and_in_the_fraction():
    ratios = np.array([1.0, 1.0, 1.0, 1.0, 1.0, 1.5])
    real = _real(ratios)
    r = ionosphere.klobuchar_ratio(real, REF, real["group_delay"], real["iono"])["G"]
    per = np.array(list(r["ratio_per_satellite"].values()))
    # least squares spreads the outlier over the bias and the scale; the ordering and the size stay
    assert per.argmax() == 5 and per[5] - np.median(per) > 0.2
    assert 0.1 < r["residual_fraction"] < 0.5
    assert ionosphere.residual_fraction({"G": r}) == pytest.approx(r["residual_fraction"])


def test_carrier_levelling_keeps_the_carrier_precision_over_noisy_code():
    real = _real(np.full(6, 0.8))
    rng = np.random.default_rng(5)
    for s in ("L1C", "L2W"):
        real["obs"]["code"][s] = real["obs"]["code"][s] + rng.normal(0, 0.3, real["obs"]["code"][s].shape)
    r = ionosphere.klobuchar_ratio(real, REF, real["group_delay"], real["iono"])["G"]
    # 21 epochs of 0.3 m code noise on each of two codes: the arc mean is good to ~0.1 m on P2-P1, ~0.06 m on I1
    assert r["mean_ratio"] == pytest.approx(0.8, abs=0.08)


def test_no_pair_or_no_model_gives_no_system():
    real = _real(np.ones(6))
    assert ionosphere.klobuchar_ratio(real, REF, real["group_delay"], {}) == {}
    real["signals"], real["freq"] = ["L1C"], real["freq"][:1]
    assert ionosphere.klobuchar_ratio(real, REF, real["group_delay"], real["iono"]) == {}
    assert ionosphere.residual_fraction({}) is None
