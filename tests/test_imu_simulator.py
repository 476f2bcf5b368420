"""ImuSimulator contract: ideal = truth, output - truth = sum of the error terms, block invariance, determinism,
increments, configuration errors and presets."""
import dataclasses
import json
import math

import numpy as np
import pytest

from simkit.errors import ScenarioError
from simkit.imu import ImuSimulator, parse_config, presets, truth_increments
from simkit.section import Section

ALL_TERMS = {
    "preset": "stim300",
    "gyro": {"rrw_deg_per_h_per_sqrt_h": 0.05, "quantization_urad": 0.5,
             "gauss_markov": [{"sigma_deg_per_h": 2.0, "tau_s": 30.0}]},
    "accel": {"rrw_ug_per_sqrt_h": 20.0, "quantization_mm_per_s": 0.01,
              "gauss_markov": [{"sigma_ug": 50.0, "tau_s": 60.0}]},
}


def truth(n, rate_hz=200.0, seed=0):
    """A smooth tumbling, accelerating motion (rad/s, m/s^2) that also saturates briefly."""
    t = np.arange(n) / rate_hz
    omega = np.stack([0.5 * np.sin(0.7 * t), 0.3 * np.cos(1.3 * t), 0.2 + 0.1 * np.sin(0.2 * t)], axis=1)
    f = np.stack([2.0 * np.sin(0.9 * t), 1.0 * np.cos(0.4 * t), 9.8 + 3.0 * np.sin(0.3 * t)], axis=1)
    omega[n // 2: n // 2 + 20, 0] = 8.0     # above the STIM300's 400 deg/s range
    return t, omega, f


def cfg(table):
    return parse_config(Section(table, "imu"))


def test_presets_listed_and_all_load():
    names = presets()
    for required in ("ideal", "stim300", "microstrain_3dm_gx3_25", "adis16488", "hg1700", "hg9900", "bmi088",
                     "badshah2015_stim300", "wu2015"):
        assert required in names
    for name in names:
        c = cfg({"preset": name})
        assert name == "ideal" or c.source, name
        json.dumps(ImuSimulator(c, 100.0, 1).attributes())


def test_paper_presets_as_printed():
    b = cfg({"preset": "badshah2015_stim300"})
    assert b.gyro.bias_turn_on == pytest.approx(4.0 * math.pi / 180 / 3600)
    assert b.gyro.random_walk == pytest.approx(1.7 * math.pi / 180 / 60)
    assert b.accel.bias_turn_on == pytest.approx(1.5e-3 * 9.80665)
    assert b.accel.random_walk == pytest.approx(0.2e-3 * 9.80665, rel=1e-3)   # 0.2 mg/sqrt(Hz)
    w = cfg({"preset": "wu2015"})
    assert w.gyro.bias_turn_on == pytest.approx(0.01 * math.pi / 180 / 3600)
    assert w.accel.bias_turn_on == pytest.approx(10e-6 * 9.80665)


def test_ideal_equals_truth():
    t, omega, f = truth(5000)
    for table in ({}, {"preset": "ideal"}):
        b = ImuSimulator(cfg(table), 200.0, 3).process(t, omega, f)
        gyro, accel, errors = b.gyro, b.accel, b.errors
        assert errors == {}
        np.testing.assert_array_equal(gyro, omega)
        np.testing.assert_array_equal(accel, f)


def test_output_minus_truth_is_sum_of_errors():
    t, omega, f = truth(20000)
    b = ImuSimulator(cfg(ALL_TERMS), 200.0, 3).process(t, omega, f)
    gyro, accel, errors = b.gyro, b.accel, b.errors
    assert {"gyro_bias", "gyro_white", "gyro_scale_misalignment", "gyro_g_sensitivity", "gyro_saturation",
            "gyro_quantization", "accel_bias", "accel_white", "accel_scale_misalignment",
            "accel_quantization"} <= set(errors)
    assert "gyro_bandwidth" not in errors          # 262 Hz is above the 100 Hz Nyquist frequency
    assert np.any(errors["gyro_saturation"] != 0)
    for name, measured, true in (("gyro", gyro, omega), ("accel", accel, f)):
        total = sum(v for k, v in errors.items() if k.startswith(name + "_"))
        scale = np.abs(measured).max()
        np.testing.assert_allclose(measured - true, total, rtol=0, atol=8 * np.finfo(float).eps * scale)
    assert np.abs(gyro).max() <= 400.0 * math.pi / 180 + 1e-6 + 0.5e-6 * 200


def test_bandwidth_term_at_high_rate():
    t, omega, f = truth(4000, rate_hz=1000.0)
    b = ImuSimulator(cfg({"preset": "stim300"}), 1000.0, 3).process(t, omega, f)
    gyro, accel, errors = b.gyro, b.accel, b.errors
    assert "gyro_bandwidth" in errors and "accel_bandwidth" in errors
    total = sum(v for k, v in errors.items() if k.startswith("gyro_"))
    np.testing.assert_allclose(gyro - omega, total, rtol=0, atol=1e-14)


@pytest.mark.parametrize("output", ["rates", "increments"])
def test_blocks_give_identical_arrays(output):
    t, omega, f = truth(12345)
    c = cfg({**ALL_TERMS, "output": output})
    one = ImuSimulator(c, 200.0, 42).process(t, omega, f)
    sim = ImuSimulator(c, 200.0, 42)
    cuts = [0, 1, 2, 7, 1000, 1001, 6000, 12345]
    parts = [sim.process(t[a:b], omega[a:b], f[a:b]) for a, b in zip(cuts[:-1], cuts[1:])]
    arrays = ("gyro", "accel") + (("dtheta", "dvel") if output == "increments" else ())
    assert (one.dtheta is None) == (output == "rates")
    for name in arrays:
        np.testing.assert_array_equal(getattr(one, name), np.concatenate([getattr(p, name) for p in parts]))
    for name in one.errors:
        np.testing.assert_array_equal(one.errors[name], np.concatenate([p.errors[name] for p in parts]))


def test_noise_drawn_ahead_gives_the_same_record():
    """The truth-independent terms (vibration, turn-on and bias sources, white) drawn ahead in pieces that do not
    match the blocks (the pipeline draws them while the truth worker computes) give the record of no draw-ahead,
    bit for bit; a sensor without such terms draws nothing."""
    t, omega, f = truth(12345)
    vib = [[5.0, 1e-4], [50.0, 1e-3], [90.0, 1e-4]]
    c = cfg({**ALL_TERMS, "accel": {**ALL_TERMS["accel"], "vibration_psd_g2_per_hz": vib}})
    one = ImuSimulator(c, 200.0, 42).process(t, omega, f)
    sim = ImuSimulator(c, 200.0, 42)
    sim.draw_ahead(500)
    sim.draw_ahead(3000)
    cuts, parts = [0, 1001, 1002, 7000, 12345], []
    for a, b in zip(cuts[:-1], cuts[1:]):
        parts.append(sim.process(t[a:b], omega[a:b], f[a:b]))
        sim.draw_ahead(2500 if a == 0 else 0)
    assert not sim.gyro.drawn and not sim.accel.drawn
    assert {"accel_vibration", "gyro_bias", "accel_white"} <= set(one.errors)
    for name in ("gyro", "accel"):
        np.testing.assert_array_equal(getattr(one, name), np.concatenate([getattr(p, name) for p in parts]))
    for name in one.errors:
        np.testing.assert_array_equal(one.errors[name], np.concatenate([p.errors[name] for p in parts]))
    ideal = ImuSimulator(cfg({"preset": "ideal"}), 200.0, 1)
    ideal.draw_ahead(100)
    assert not ideal.gyro.drawn and not ideal.accel.drawn


def test_deterministic_and_seed_dependent():
    t, omega, f = truth(2000)
    a = ImuSimulator(cfg(ALL_TERMS), 200.0, 5).process(t, omega, f)
    b = ImuSimulator(cfg(ALL_TERMS), 200.0, 5).process(t, omega, f)
    c = ImuSimulator(cfg(ALL_TERMS), 200.0, 6).process(t, omega, f)
    np.testing.assert_array_equal(a.gyro, b.gyro)
    assert not np.array_equal(a.gyro, c.gyro)


def test_changing_accel_does_not_change_gyro_noise():
    t, omega, f = truth(2000)
    other = {**ALL_TERMS, "accel": {"vrw_m_per_s_per_sqrt_h": 1.0}}
    a = ImuSimulator(cfg(ALL_TERMS), 200.0, 5).process(t, omega, f)
    b = ImuSimulator(cfg(other), 200.0, 5).process(t, omega, f)
    np.testing.assert_array_equal(a.gyro, b.gyro)


def test_truth_increments_exact_for_quadratics():
    dt = 0.01
    t = np.arange(50) * dt
    x = np.stack([1 + 2 * t - 3 * t**2, np.full_like(t, 0.5), t**2], axis=1)
    inc = truth_increments(x, None, dt)

    def antiderivative(s):
        return np.stack([s + s**2 - s**3, 0.5 * s, s**3 / 3], axis=1)
    exact = antiderivative(t[2:]) - antiderivative(t[1:-1])
    np.testing.assert_allclose(inc[2:], exact, rtol=1e-12, atol=1e-15)


def test_increments_output():
    t, omega, f = truth(3000)
    block = ImuSimulator(cfg({**ALL_TERMS, "output": "increments"}), 200.0, 9).process(t, omega, f)
    assert [f.name for f in dataclasses.fields(block)] == ["gyro", "accel", "dtheta", "dvel", "errors"]
    assert not isinstance(block, tuple)
    gyro, errors = block.gyro, block.errors
    dt = 1 / 200.0
    np.testing.assert_allclose(block.dtheta / dt, gyro, rtol=1e-15)
    np.testing.assert_allclose(block.dvel / dt, block.accel, rtol=1e-15)
    q = 0.5e-6
    k = block.dtheta / q
    np.testing.assert_allclose(k, np.round(k), atol=1e-6)     # whole LSBs
    total = sum(v for n, v in errors.items() if n.startswith("gyro_"))
    np.testing.assert_allclose(gyro - truth_increments(omega, None, dt) / dt, total, rtol=0, atol=1e-12)


@pytest.mark.parametrize("table, key", [
    ({"preset": "stim300", "gyro": {"arw_deg_per_h": 1.0}}, "imu.gyro.arw_deg_per_h"),
    ({"preset": "nope"}, "imu.preset"),
    ({"gyro": {"arw_deg_per_sqrt_h": -1.0}}, "imu.gyro.arw_deg_per_sqrt_h"),
    ({"accel": {"gauss_markov": [{"sigma_ug": 1.0}]}}, "imu.accel.gauss_markov[0].tau_s"),
    ({"accel": {"gauss_markov": [{"sigma_ug": 1.0, "tau_s": 3.0, "extra": 1}]}}, "imu.accel.gauss_markov[0].extra"),
    ({"output": "counts"}, "imu.output"),
    ({"gyro": {"scale_factor_nonlinearity_ppm": 10.0}}, "imu.gyro.scale_factor_nonlinearity_ppm"),
    ({"rate_hz": 0}, "imu.rate_hz"),
    ({"magnetometer": {}}, "imu.magnetometer"),
])
def test_config_errors_name_the_key(table, key):
    with pytest.raises(ScenarioError) as err:
        cfg(table)
    assert err.value.key == key


def test_overrides_beat_preset():
    c = cfg({"preset": "stim300", "rate_hz": 400, "gyro": {"arw_deg_per_sqrt_h": 0.3}})
    assert c.rate_hz == 400.0
    assert c.gyro.random_walk == pytest.approx(0.3 * math.pi / 180 / 60)
    assert c.gyro.bias_instability == pytest.approx(0.4518 * math.pi / 180 / 3600)


def test_allan_command(tmp_path):
    import argparse

    import h5py

    from simkit.commands import allan as cmd

    rate, n = 100.0, 60000
    t = np.arange(n) / rate
    c = cfg({"gyro": {"arw_deg_per_sqrt_h": 0.5}})
    b = ImuSimulator(c, rate, 1).process(t, np.zeros((n, 3)), np.zeros((n, 3)))
    gyro, accel = b.gyro, b.accel
    path = tmp_path / "imu.h5"
    with h5py.File(path, "w") as h5:
        h5.attrs["schema_version"] = 1     # a simkit file (simkit.open checks it)
        h5["imu/t"], h5["imu/gyro"], h5["imu/accel"] = t, gyro, accel
    parser = argparse.ArgumentParser()
    cmd.add_parser(parser.add_subparsers())
    args = parser.parse_args(["allan", str(path), "--json", str(tmp_path / "a.json"),
                              "--plot", str(tmp_path / "a.png")])
    assert cmd.run(args) == 0
    fitted = json.loads((tmp_path / "a.json").read_text())["fit"]
    for axis in "xyz":
        assert fitted[axis]["N"] == pytest.approx(0.5 * math.pi / 180 / 60, rel=0.15)
    assert (tmp_path / "a.png").stat().st_size > 0
    with pytest.raises(Exception) as err:
        cmd.run(parser.parse_args(["allan", str(tmp_path / "a.json")]))
    assert "a.json" in str(err.value)
