"""DD attitude with five systems: Galileo and QZSS join the integer fixing, GLONASS (FDMA) is left out with the
reason given, and fixing is at least as frequent as with GPS + BDS alone, with no wrong fix against the true
integer ambiguities the file holds."""
import numpy as np
import pytest

import simkit
from simkit.attitude import SOLVERS, AttitudeInputError

pytestmark = pytest.mark.slow  # two 5-minute, three-antenna simulations and their solves


def _run(tmp, name, signals):
    return simkit.run("xian_static_bds", out=tmp / f"{name}.h5", overrides=[
        'scenario.start="2026-04-27T06:05:00Z"', "scenario.duration_s=300", "imu.preset=ideal",
        "gnss.constellation=[{source='BRDM00DLR_S_20261170000_01D_MN.rnx.gz'}]", f"gnss.signals={signals}"])


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("att5")
    return _run(tmp, "gc", '["L1C","B1I"]'), _run(tmp, "five", '["L1C","B1I","E1C","G1C"]')


def test_five_systems_fix_at_least_as_often_with_no_wrong_fix(files):
    rates = []
    for path in files:
        with simkit.open(path) as ds:
            sol = SOLVERS["attitude"](ds, {"every": 2}, False)
        st = sol.extras["status"]
        assert (st == 3).sum() == 0  # status 3: a fix that differs from the true integers
        fixed = st == 1
        z, zt = sol.extras["dd_ambiguity"][fixed], sol.extras["dd_ambiguity_true"][fixed]
        assert np.array_equal(z[~np.isnan(z)], zt[~np.isnan(zt)])
        rates.append(fixed.mean())
        if path == files[1]:
            assert sol.config["signals"] == ["L1C", "B1I", "E1C"]  # G1C left out
    print(f"\nDD attitude fix rate: GPS+BDS {rates[0]:.3f}, five systems {rates[1]:.3f}")
    assert rates[1] >= rates[0]


def test_naming_a_glonass_signal_is_refused_with_the_reason(files):
    with simkit.open(files[1]) as ds:
        with pytest.raises(AttitudeInputError, match="G1C.*not integers"):
            SOLVERS["attitude"](ds, {"signals": "L1C,G1C"}, False)
