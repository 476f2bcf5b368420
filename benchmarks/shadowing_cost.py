"""CPU cost of the street-shadowing channel ([gnss.shadowing], docs/shadowing.md): a 30-minute drive at 10 Hz, two
antennas, GPS L1C + BDS B1I, simulated with and without it, twice each (alternating, so a warm-up or a neighbour's
load shows as a difference between the pairs).

Run: python benchmarks/shadowing_cost.py [OUT_DIR]
"""
import sys
import time
from pathlib import Path

from simkit.pipeline import run

ROOT = Path(__file__).resolve().parents[1]
SHADOW = {"elevation_deg": [0.0, 30.0, 60.0], "shadowed_probability": [0.4, 0.3, 0.1],
          "blocked_probability": [0.3, 0.1, 0.0], "dwell_s": [10.0, 5.0, 8.0], "attenuation_mean_db": 8.0,
          "attenuation_sigma_db": 3.0, "attenuation_correlation_s": 3.0}


def scenario(shadowing, duration=1800.0, rate=10.0):
    nav = ROOT / "simkit" / "data" / "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"
    gnss = {"rate_hz": rate, "elevation_mask_deg": 10.0, "signals": ["L1C", "B1I"],
            "constellation": [{"source": str(nav)}],
            "antenna": [{"lever_arm_m": [0, 0, 0]}, {"lever_arm_m": [1, 0, 0]}]}
    if shadowing:
        gnss["shadowing"] = SHADOW
    return {"scenario": {"name": "shadow_cost", "start": "2026-04-27T06:00:00Z", "duration_s": duration, "seed": 3},
            "trajectory": {"rate_hz": rate, "origin": {"lat_deg": 34.2, "lon_deg": 108.9, "height_m": 400.0},
                           "initial": {"speed_m_per_s": 10.0, "heading_deg": 45.0},
                           "segment": [{"kind": "cruise", "duration_s": duration}]},
            "gnss": gnss}


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    for shadowing in (False, True, False, True):
        t0 = time.process_time()
        run(scenario(shadowing), out=out / f"shadow_cost_{int(shadowing)}.h5", force=True)
        print(f"{'with' if shadowing else 'without'} shadowing: {time.process_time() - t0:.2f} s CPU")


if __name__ == "__main__":
    main()
