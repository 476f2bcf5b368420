"""simkit's kf15 against pyins' feedback filter (peer implementation, PyPI python-ins) on the same simkit files:
same initial state, the same GNSS fixes (including the one at the initial epoch, which both filters use), lever
arm and noise model.

Over 8 seeds of ``quickstart`` (40 s, 2 Hz GNSS, ADIS16488), the RMS over the runs of each filter's per-run RMS
error must satisfy simkit <= pyins x 1.05 on all 9 axes (position ENU, velocity ENU, pitch, roll, heading).
Measured (seeds 1-8): simkit / pyins = 0.988, 1.003, 1.003, 1.000, 0.998, 0.985, 0.977, 1.016, 1.022; before kf15
used the fix at the initial epoch (pyins always did) the same runs gave 1.005, 1.031, 1.047, 0.996, 0.993,
1.002, 1.030, 1.033, 1.076 (heading fails). The 5 %
tolerance: the per-run ratio scatters by at most 7 % (1 sigma, heading and roll: both filters are near-optimal
and differ only by second-order terms of their error models), so the 8-run figure has a standard error of at
most 2.5 %; 5 % is two standard errors."""
import numpy as np
import pytest

import simkit
from simkit.estimators.registry import SOLVERS, merged
from studies.evaluate import rms_table
from studies.pyins_peer import PARAMS, run_pyins

AXES = ["pos_E", "pos_N", "pos_U", "vel_E", "vel_N", "vel_U", "pitch", "roll", "heading"]


@pytest.mark.slow
def test_kf15_is_at_least_as_accurate_as_pyins_on_every_axis(tmp_path):
    ours, theirs = [], []
    for seed in range(1, 9):
        path = simkit.run("quickstart", out=tmp_path / f"q{seed}.h5", seed=seed,
                          overrides=["scenario.duration_s=40", "gnss.rate_hz=2.0"])
        with simkit.open(path) as ds:
            p = merged("kf15", {**PARAMS, "init_heading_error_deg": 0.5, "seed": seed})
            ours.append(rms_table(ds, SOLVERS["kf15"](ds, p, False), 10.0))
            theirs.append(rms_table(ds, run_pyins(ds, p)[0], 10.0))
    ours, theirs = np.sqrt(np.mean(np.square(ours), 0)), np.sqrt(np.mean(np.square(theirs), 0))
    print("simkit", ours.round(4), "\npyins ", theirs.round(4), "\nratio ", (ours / theirs).round(3))
    worse = [f"{a}: {o:.4g} vs {t:.4g}" for a, o, t in zip(AXES, ours, theirs) if not o <= 1.05 * t]
    assert not worse, "simkit kf15 less accurate than pyins: " + "; ".join(worse)
