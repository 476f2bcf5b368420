"""SPP on a real file against SPP on its calibrated twin over several seeds (docs/real_data.md).

A 9-minute twin is one draw of the truth-side errors (ionosphere residual field, troposphere offsets, broadcast
orbit and clock errors): its SPP error is a sample, so the real file's error is compared with the spread of the
twin's over ``--seeds`` runs of the calibrated scenario (the scenario stored in DIR/twin_fit.h5).

Run: python benchmarks/twin_spp.py DIR [--seeds 10] [--systems GC] [--set KEY=VALUE ...]
(DIR: the output folder of ``simkit twin OBS --nav NAV -o DIR --fit``)
"""
import argparse
import json
import tempfile
import tomllib
from pathlib import Path

import numpy as np

import simkit
from simkit import api
from simkit.io import open_dataset, write_solution


def spp_rms(path, systems):
    sol = api.solve(path, ["spp"], {"systems": systems})["spp"]
    write_solution(path, "spp", sol)
    return api.score(path, path, solution="spp").statistics["position_3d"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir")
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--systems", default="GC")
    ap.add_argument("--set", action="append", default=[], dest="overrides")
    args = ap.parse_args()
    d = Path(args.dir)
    with open_dataset(d / "twin_fit.h5") as ds:
        scenario = tomllib.loads(ds.attrs["scenario_toml"])
    with tempfile.TemporaryDirectory() as tmp:
        real = Path(tmp) / "real.h5"
        real.write_bytes((d / "real.h5").read_bytes())
        r = spp_rms(real, args.systems)
        twins = []
        for seed in range(1, args.seeds + 1):
            out = simkit.run(scenario, out=Path(tmp) / f"s{seed}.h5", seed=seed, overrides=args.overrides)
            twins.append(spp_rms(out, args.systems)["rms"])
    twins = np.array(twins)
    print(json.dumps({"real_3d_rms_m": round(r["rms"], 3), "real_3d_p95_m": round(r["p95"], 3),
                      "twin_3d_rms_m_per_seed": np.round(twins, 3).tolist(),
                      "twin_median_m": round(float(np.median(twins)), 3),
                      "twin_rms_over_seeds_m": round(float(np.sqrt(np.mean(twins ** 2))), 3),
                      "real_over_twin_median": round(float(r["rms"] / np.median(twins)), 3),
                      "real_over_twin_rms": round(float(r["rms"] / np.sqrt(np.mean(twins ** 2))), 3)}, indent=1))


if __name__ == "__main__":
    main()
