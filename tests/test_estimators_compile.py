"""What the filter loop compiles on a cold numba cache (simkit/estimators/loop.py, module docstring): the Kalman
loop leaves the H-infinity correction uncompiled, and each kernel it calls has one specialisation. Run in a
fresh process with an empty NUMBA_CACHE_DIR and no prepared cache (with a warm cache nothing compiles and there
is nothing to see)."""
import json
import os
import subprocess
import sys

import pytest

from conftest import ROOT

CHILD = r"""
import json
import numpy as np
from simkit.estimators import FilterConfig, GnssFixes, ImuData, InitialState, KalmanFilter15, kalman, loop
n = 201  # 2 s at 100 Hz, static and level at the equator
t = np.arange(n) / 100.0
imu = ImuData(t, np.zeros((n, 3)), np.tile([0.0, 0.0, 9.78], (n, 1)))
init = InitialState(0.0, np.array([0.0, 0.0, 0.0]), np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))
gnss = GnssFixes(np.array([1.0, 2.0]), np.tile([6378137.0, 0.0, 0.0], (2, 1)), np.zeros((2, 3)),
                 np.full(3, 0.5), np.full(3, 0.05), np.zeros(3))
sol = KalmanFilter15(FilterConfig(), init).run(imu, gnss)
kernels = [f for m in (loop, kalman) for f in vars(m).values() if hasattr(f, "signatures")]
print(json.dumps({"specialisations": {f.__name__: len(f.signatures) for f in kernels},
                  "finite": bool(np.isfinite(sol.pos_ecef).all())}))
"""


@pytest.mark.slow
def test_the_kalman_loop_compiles_no_hinf_kernel_and_one_specialisation_each(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), SIMKIT_NO_PREPARED_CACHE="1")  # compiled
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])
    out = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stderr
    got = json.loads(out.stdout.strip().splitlines()[-1])
    spec = got["specialisations"]
    assert got["finite"]
    assert spec["run"] == 1 and spec["correct"] == 1
    assert spec["correct_hinf"] == spec["weighted_theta"] == spec["hinf_gamma"] == spec["_hinf"] == 0, spec
    assert max(spec.values()) == 1, spec  # a literal argument or a layout change would add a second one
