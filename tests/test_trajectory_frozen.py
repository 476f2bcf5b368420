"""The truth and the IMU output against the arrays of commit 9857d6a (tests/data/frozen, SOURCES.md): the closed-form
attitude truth, the shared sines and cosines and the chunk-aligned blocks of issue 25 reorder float operations, so
they agree with the old numbers to roundoff, not bit for bit. The bound agreed: 1e-12 relative to each dataset's
largest value (found: 1e-15; 2e-15 over the 600 s benchmark run; with the tangent-based sines and cosines of
the third round 1.2e-15, and over the 600 s run 1.7e-15, the bandwidth error term within 1.1e-13 m/s^2: the
specific force's roundoff, 1.7e-15 of its largest value); the Euler triple within 1e-12 rad away from 90 deg of pitch, where the old
conversion from a rotation lost digits (3.6e-12 rad at 0.0006 deg from it) and the new one reads the angles."""
from pathlib import Path

import h5py
import numpy as np
from truth_imu_scenario import truth_imu_toml

import simkit

FROZEN = Path(__file__).parent / "data" / "frozen" / "truth_imu_9857d6a.npz"


def test_truth_and_imu_agree_with_the_arrays_before_the_reformulation(tmp_path):
    out = simkit.run(str(truth_imu_toml(tmp_path, 20.0)), out=tmp_path / "s.h5")
    old = np.load(FROZEN)
    with h5py.File(out, "r") as f:
        assert len(old.files) == 11
        for key in old.files:
            name = key.replace(".", "/")
            new, ref = f[name][()], old[key]
            assert new.shape == ref.shape, name
            if name.endswith("/t"):
                np.testing.assert_array_equal(new, ref)
            elif name == "truth/euler":
                away = np.cos(ref[:, 0]) > 0.01
                diff = (new - ref + np.pi) % (2.0 * np.pi) - np.pi
                assert np.abs(diff[away]).max() < 1e-12
            else:
                assert np.abs(new - ref).max() <= 1e-12 * np.abs(ref).max(), name
