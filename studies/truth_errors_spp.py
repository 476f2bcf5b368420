"""SPP error with and without the truth-side errors (docs/truth_errors.md), GPS L1 C/A and BDS B1I, several seeds.

Each case is the three CLI commands a user types (run from the repository root):

    python -m simkit run examples/truth_errors_static.toml -o F.h5 --seed N --set gnss.signals='["L1C"]' \
        [--set gnss.truth_errors.model='none']
    python -m simkit solve F.h5 --filter spp -q
    python -m simkit score F.h5 F.h5 --json F.json

and the table is the mean over seeds of the score's position_3d RMS and 95 % values (and their range).
Usage: python studies/truth_errors_spp.py OUT_DIR [N_SEEDS [KEY=VALUE ...]]; each KEY=VALUE is one more --set
(e.g. gnss.errors.noise=false gnss.errors.multipath=false for the error budget of the models alone).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def case(out: Path, signal: str, model: str, seed: int, extra: list[str]) -> dict:
    f = out / f"{signal}_{model}_{seed}.h5"
    if f.with_suffix(".json").is_file():     # done by an earlier call with the same OUT_DIR
        return json.loads(f.with_suffix(".json").read_text())["statistics"]
    sim = [sys.executable, "-m", "simkit"]
    subprocess.run(sim + ["run", "examples/truth_errors_static.toml", "-o", str(f), "--seed", str(seed),
                          "--set", f'gnss.signals=["{signal}"]', "--set", f"gnss.truth_errors.model='{model}'"]
                   + [x for kv in extra for x in ("--set", kv)],
                   cwd=ROOT, check=True, capture_output=True)
    subprocess.run(sim + ["solve", str(f), "--filter", "spp", "-q"], cwd=ROOT, check=True, capture_output=True)
    subprocess.run(sim + ["score", str(f), str(f), "--json", str(f.with_suffix(".json"))], cwd=ROOT, check=True,
                   capture_output=True)
    f.unlink()
    return json.loads(f.with_suffix(".json").read_text())["statistics"]


def main() -> None:
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    seeds = range(1, 1 + (int(sys.argv[2]) if len(sys.argv) > 2 else 6))
    extra = sys.argv[3:]
    print("| signal | truth_errors | 3-D RMS m (mean, min-max) | 3-D 95 % m (mean, min-max) | horizontal RMS m | up RMS m |")
    print("|---|---|---|---|---|---|")
    for signal in ("L1C", "B1I"):
        for model in ("realistic", "none"):
            st = [case(out, signal, model, s, extra) for s in seeds]
            rms = np.array([s["position_3d"]["rms"] for s in st])
            p95 = np.array([s["position_3d"]["p95"] for s in st])
            h = np.mean([s["horizontal"]["rms"] for s in st])
            up = np.mean([s["up"]["rms"] for s in st])
            print(f"| {signal} | {model} | {rms.mean():.2f} ({rms.min():.2f}-{rms.max():.2f}) | {p95.mean():.2f} "
                  f"({p95.min():.2f}-{p95.max():.2f}) | {h:.2f} | {up:.2f} |", flush=True)


if __name__ == "__main__":
    main()
