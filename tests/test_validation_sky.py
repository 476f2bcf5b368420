"""C1-C5 on real constellation geometry: the Xi'an three-antenna setup under the nominal 2016 BDS-2 sky and the
bundled 2026 BDS-3 broadcast ephemerides, every satellite count, highest and random subsets."""
import pytest

from simkit.scenario import load
from simkit.validation import geometry
from simkit.validation.summary import validate

SKIES = {
    "bds2_nominal": [],
    "bds3_broadcast": ['scenario.start="2026-04-27T06:00:00Z"',
                       "gnss.constellation[0].source=BRDM00DLR_S_20261170000_01D_MN.rnx.gz"],
}


@pytest.mark.parametrize("sky", SKIES)
def test_mathematical_claims_hold_for_every_satellite_count(sky):
    sc = load("xian_static_bds", SKIES[sky] + ["scenario.duration_s=7200", "gnss.rate_hz=0.02"])
    geo = geometry.select_systems(geometry.from_scenario(sc), "C")
    s = validate(geo, n_random=2, seed=1, random_stride=1).summary
    for claim in ("C1", "C2", "C3", "C4", "C5"):
        assert s["claims"][claim]["held"] and s["claims"][claim]["checked"] > 0, claim
    top = s["visible"]["max"]
    assert top >= 8
    for group, per_k in s["ranks"].items():
        dual = group.startswith("dual")
        assert set(per_k) <= {str(k) for k in range(2, top + 1)} and "2" in per_k and str(top) in per_k
        for k, ranks in per_k.items():
            want = (1 if k == "2" else 2) if dual else (2 if k == "2" else 3)
            assert set(ranks) == {str(want)}, (group, k, ranks)
    for claim in ("C6", "C7", "C7_all_visible"):
        assert 0.5 < s["claims"][claim]["fraction"] <= 1.0
