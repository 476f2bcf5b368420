"""Wang 2018's observability claims over Galileo, GLONASS and QZSS alone and all five systems together: the
mathematical claims C1-C5 (closed forms and ranks of the paper's Theorems 1 and 2) hold for every system's
geometry, and the combined sky has every system's satellites."""
import pytest

import simkit

OVER = ['scenario.start="2022-06-08T10:20:00Z"', "scenario.duration_s=120",
        "gnss.constellation=[{source='KMS300DNK_R_20221591000_01H_MN.rnx.gz'}]",
        'gnss.signals=["L1C","B1I","E1C","G1C","J1C"]']


@pytest.mark.parametrize("systems", [None, "E", "R", "G,J", "G,C,E,J,R"])
def test_mathematical_claims_hold_per_system_and_combined(systems):
    v = simkit.validate("xian_static_bds", overrides=OVER, systems=systems, random_stride=30)
    assert not v.mathematical_failure
    sats = v.summary["satellites"]
    letters = set((systems or "GCEJR").replace(",", ""))
    assert {s[0] for s in sats} == letters
    if systems in (None, "G,C,E,J,R"):
        assert v.summary["visible"]["min"] >= 20
