"""Default ambiguity validation of the attitude solvers on a simulated airborne file: single-epoch resolution at
forced satellite counts must not accept more wrong fixes than the tolerated failure rate pf allows
(docs/attitude.md, "Validation at low satellite counts"), and the solutions record the signals they used."""
import pytest

import simkit
from simkit.attitude import SOLVERS
from studies.attitude import validation_table, wrong_fix_bound

pytestmark = pytest.mark.slow  # simulates a 1000 s file (~5 s) and solves it 23 times (minutes under load)


@pytest.fixture(scope="module")
def air(tmp_path_factory):
    """Badshah's airborne flight, GPS L1 + BDS B1I, three antennas, 1001 epochs at 1 Hz."""
    out = tmp_path_factory.mktemp("att") / "air.h5"
    return simkit.run("airborne_stim300", out=out)


# C-/MC-LAMBDA search for long at 4-6 satellites (minutes per 1001 epochs): thinned, MC-LAMBDA with a work cap
# (an unfinished search is never accepted, so the cap cannot add wrong fixes).
THIN = {"attitude": {}, "attitude_c": {"every": 5}, "attitude_mc": {"every": 10, "max_nodes": 200_000}}


@pytest.mark.parametrize("name", ["attitude", "attitude_c", "attitude_mc"])
def test_default_validation_keeps_wrong_fixes_within_pf_at_every_satellite_count(air, name):
    """Bound: if each epoch accepts a wrong fix with probability <= pf = 0.001 (the default), the wrong fixes of N
    epochs exceed the 99.9 % quantile of Binomial(N, pf) with probability <= 0.001 per row (5 of 1001, 2 of 201
    or 101 epochs). 4 satellites: GPS L1 alone (with two systems, 4 satellites leave at most 2 double differences
    per baseline). With all satellites the fixes must stay those of the previous default (ratio test 3 alone)."""
    kw = THIN[name]
    with simkit.open(air) as ds:
        rows = validation_table(ds, names=(name,), counts=(5, 6, 7, 8, 0), **kw)
        rows += validation_table(ds, names=(name,), counts=(4,), signals="L1C", **kw)
        old = validation_table(ds, names=(name,), counts=(0,), validation="ratio", **kw)[0]
    for r in rows:
        assert r["epochs"] > 0.9 * 1001 / kw.get("every", 1), r
        assert r["wrong"] <= wrong_fix_bound(r["epochs"], 0.001), r
    full = next(r for r in rows if r["sats"] == "all")
    assert full["fixed"] >= 0.99 * old["fixed"] and old["fixed"] > 0.99 * old["epochs"], (full, old)


def test_the_ratio_test_alone_exceeds_the_bound_where_the_default_holds_it(air):
    """The defect's evidence: the ratio test 3 alone (the previous default), GPS L1 with 4 satellites, accepts
    more wrong fixes than the binomial bound of pf = 0.001 allows, so the test above can fail."""
    with simkit.open(air) as ds:
        (r,) = validation_table(ds, names=("attitude",), counts=(4,), signals="L1C", validation="ratio")
    assert r["wrong"] > wrong_fix_bound(r["epochs"], 0.001), r


def test_solutions_record_the_signals_they_used(air):
    with simkit.open(air) as ds:
        have = [str(s) for s in ds["gnss/signals"][:]]
        sol = SOLVERS["attitude"](ds, {"stop_s": 5.0}, False)
        one = SOLVERS["attitude"](ds, {"stop_s": 5.0, "signals": have[1]}, False)
        tdcp = SOLVERS["tdcp"](ds, {"stop_s": 5.0}, False)
    assert sol.config["signals"] == have and tdcp.config["signals"] == have and len(have) == 2
    assert one.config["signals"] == [have[1]]
