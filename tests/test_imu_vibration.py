"""Vibration from a PSD table: Welch PSD and RMS against the configured one-sided profile, block invariance,
the error identity, and malformed tables."""
import math

import numpy as np
import pytest
from scipy import signal

from simkit.errors import ScenarioError
from simkit.imu import ImuSimulator, parse_config
from simkit.imu.vibration import band_variance
from simkit.section import Section

G0 = 9.80665
RATE = 1000.0
# A MIL-STD-810-style random-vibration profile (one-sided g^2/Hz), ramps of +/-6 dB/oct, cut below Nyquist
ACCEL_PSD = [[20.0, 0.01], [80.0, 0.04], [350.0, 0.04], [480.0, 0.01]]
# Gyro: (deg/s)^2/Hz, a falling profile with a non-power-of-two slope
GYRO_PSD = [[5.0, 1e-3], [40.0, 2e-4], [200.0, 5e-5]]


def cfg(table):
    return parse_config(Section(table, "imu"))


def loglog_psd(table, f):
    """Reference profile: log-log interpolation between table points, zero outside (MIL-STD-810 convention)."""
    fp, sp = np.log(np.array(table)[:, 0]), np.log(np.array(table)[:, 1])
    inside = (f >= table[0][0]) & (f <= table[-1][0])
    out = np.zeros_like(f)
    out[inside] = np.exp(np.interp(np.log(f[inside]), fp, sp))
    return out


def numeric_variance(table):
    """Integral of the one-sided profile by dense trapezoid quadrature (independent of the closed form)."""
    f = np.geomspace(table[0][0], table[-1][0], 200001)
    return np.trapezoid(loglog_psd(table, f), f)


def vibration(n, blocks=1, seed=7):
    sim = ImuSimulator(cfg({"accel": {"vibration_psd_g2_per_hz": ACCEL_PSD},
                            "gyro": {"vibration_psd_deg2_per_s2_per_hz": GYRO_PSD}}), RATE, seed)
    t = np.arange(n) / RATE
    zeros = np.zeros((n, 3))
    cuts = np.linspace(0, n, blocks + 1).astype(int) if blocks > 1 else np.array([0, n])
    if blocks > 1:   # uneven cuts, including tiny ones
        cuts = np.unique(np.concatenate([cuts, [1, 2, 3, 17, n // 3 + 5]]))
    out = [sim.process(t[a:b], zeros[a:b], zeros[a:b]) for a, b in zip(cuts[:-1], cuts[1:])]
    acc = np.concatenate([o.accel for o in out])
    gyro = np.concatenate([o.gyro for o in out])
    errs = {k: np.concatenate([o.errors[k] for o in out]) for k in out[0].errors}
    return gyro, acc, errs


@pytest.fixture(scope="module")
def record():
    return vibration(200_000)


@pytest.mark.parametrize("sensor,table,unit", [("accel", ACCEL_PSD, G0), ("gyro", GYRO_PSD, math.pi / 180)])
def test_welch_psd_matches_profile_per_band(record, sensor, table, unit):
    x = record[2][f"{sensor}_vibration"] / unit
    f, pxx = signal.welch(x, fs=RATE, nperseg=4096, axis=0)     # one-sided density, like the table
    ref = loglog_psd(table, f)
    for (f1, _), (f2, _) in zip(table[:-1], table[1:]):
        band = (f >= f1) & (f <= f2)
        ratio = pxx[band].mean(axis=0) / ref[band].mean()
        assert np.all(np.abs(ratio - 1.0) < 0.10), (sensor, f1, f2, ratio)
    outside = (f < 0.7 * table[0][0]) | (f > 1.3 * table[-1][0])
    assert pxx[outside].max() < 0.01 * max(p for _, p in table)


@pytest.mark.parametrize("sensor,table,unit", [("accel", ACCEL_PSD, G0), ("gyro", GYRO_PSD, math.pi / 180)])
def test_rms_is_sqrt_of_psd_integral(record, sensor, table, unit):
    rms = np.sqrt(np.mean((record[2][f"{sensor}_vibration"] / unit) ** 2, axis=0))
    grms = math.sqrt(numeric_variance(table))
    np.testing.assert_allclose(rms, grms, rtol=0.05)


def test_grms_of_navmat_p9492_profile():
    """NAVMAT P-9492 screening profile (20-80 Hz +3 dB/oct, 0.04 g^2/Hz to 350 Hz, -3 dB/oct to 2 kHz): 6.06 grms."""
    table = [[20.0, 0.01], [80.0, 0.04], [350.0, 0.04], [2000.0, 0.007]]
    assert math.sqrt(band_variance(np.array(table)).sum()) == pytest.approx(6.06, abs=0.01)
    assert math.sqrt(numeric_variance(table)) == pytest.approx(6.06, abs=0.01)


def test_output_is_truth_plus_vibration_and_axes_independent(record):
    gyro, acc, errs = record
    assert set(errs) == {"gyro_vibration", "accel_vibration"}
    np.testing.assert_array_equal(acc, errs["accel_vibration"])
    np.testing.assert_array_equal(gyro, errs["gyro_vibration"])
    c = np.corrcoef(acc.T)
    assert np.all(np.abs(c[~np.eye(3, dtype=bool)]) < 0.02)


def test_one_block_equals_many_blocks():
    one = vibration(40_000, blocks=1)
    many = vibration(40_000, blocks=7)
    for a, b in zip(one[:2], many[:2]):
        np.testing.assert_array_equal(a, b)
    for k in one[2]:
        np.testing.assert_array_equal(one[2][k], many[2][k])
    other = vibration(1000, seed=8)
    assert not np.array_equal(other[1], one[1][:1000])


def test_with_other_terms_error_identity_holds():
    table = {"preset": "stim300", "accel": {"vibration_psd_g2_per_hz": ACCEL_PSD, "bandwidth_hz": 262.0}}
    sim = ImuSimulator(cfg(table), RATE, 3)
    n = 5000
    t = np.arange(n) / RATE
    omega = np.stack([0.1 * np.sin(t), 0.2 * np.cos(t), 0.05 + 0 * t], axis=1)
    f = np.stack([0.5 * np.sin(2 * t), 0 * t, 9.8 + 0 * t], axis=1)
    block = sim.process(t, omega, f)
    accel, errors = block.accel, block.errors
    assert "accel_vibration" in errors and "gyro_vibration" not in errors
    np.testing.assert_allclose(accel - f, sum(v for k, v in errors.items() if k.startswith("accel_")),
                               atol=1e-12)
    # enabling vibration does not change the other terms' noise (own random stream)
    base = ImuSimulator(cfg({"preset": "stim300", "accel": {"bandwidth_hz": 262.0}}), RATE, 3).process(t, omega, f)
    np.testing.assert_array_equal(base.errors["accel_bias"], errors["accel_bias"])


def test_default_off():
    c = cfg({"preset": "stim300"})
    assert c.accel.vibration_psd == () and c.gyro.vibration_psd == ()
    assert cfg({}).accel.is_ideal


@pytest.mark.parametrize("value", [
    [1.0, 2.0],                          # not pairs
    [[10.0, 0.01, 3.0], [20.0, 0.01]],   # not pairs
    [[10.0, 0.01]],                      # a single point
    [[10.0, "x"], [20.0, 0.01]],         # not numbers
    [[0.0, 0.01], [20.0, 0.01]],         # non-positive frequency
    [[10.0, 0.0], [20.0, 0.01]],         # non-positive PSD
    [[10.0, -1.0], [20.0, 0.01]],
    [[20.0, 0.01], [20.0, 0.02]],        # frequencies not increasing
    [[30.0, 0.01], [20.0, 0.02]],
    "0.04",
])
def test_malformed_table_names_the_key(value):
    with pytest.raises(ScenarioError) as e:
        cfg({"accel": {"vibration_psd_g2_per_hz": value}})
    assert e.value.key == "imu.accel.vibration_psd_g2_per_hz"


def test_above_nyquist_and_too_low_name_the_key():
    c = cfg({"gyro": {"vibration_psd_deg2_per_s2_per_hz": [[10.0, 1e-3], [600.0, 1e-3]]}})
    with pytest.raises(ScenarioError) as e:
        ImuSimulator(c, RATE, 1)
    assert e.value.key == "imu.gyro.vibration_psd_deg2_per_s2_per_hz" and "Nyquist" in str(e.value)
    ImuSimulator(c, 1200.0, 1)      # 600 Hz is the Nyquist frequency at 1.2 kHz: allowed
    c = cfg({"accel": {"vibration_psd_g2_per_hz": [[1e-3, 1e-3], [10.0, 1e-3]]}})
    with pytest.raises(ScenarioError) as e:
        ImuSimulator(c, RATE, 1)
    assert e.value.key == "imu.accel.vibration_psd_g2_per_hz"
