"""Every array of the observables stage of ``bench_gnss.py`` from two checkouts, compared: the largest absolute
difference per array (observables, error terms, truth geometry and clocks, satellite states) and whether the NaN
patterns agree. Each tree runs in its own interpreter with its ``simkit`` first on ``sys.path``.

    git worktree add /tmp/before <rev>; python benchmarks/gnss_ab.py /tmp/before . [--minutes 15]
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent

PROBE = r"""
import sys
sys.path.insert(0, sys.argv[1]); sys.path.append(sys.argv[2])
import numpy as np
from simkit.constellation import load_sky
from simkit.gnss import GnssSimulator
from simkit.trajectory import Trajectory
from bench_gnss import scenario
sc = scenario(float(sys.argv[4]) / 60.0)
sim = GnssSimulator(sc.gnss, load_sky(sc.gnss.sources, sc.gnss.nav_systems), sc.start_week, sc.start_sow, sc.seed,
                    sc.duration_s)
import dataclasses
out = {}
def keep(prefix, obj):
    for f in dataclasses.fields(obj):
        v = getattr(obj, f.name)
        if isinstance(v, np.ndarray) and (f.name in ("sat_pos_ecef", "sat_clock") or v.ndim >= 2):
            out.setdefault(prefix + f.name, []).append(np.asarray(v, dtype=float))
for tr in Trajectory(sc.trajectory, sc.duration_s).blocks(rate_hz=sc.gnss.rate_hz, block_samples=300):
    ep = sim.process(tr.t, tr.pos_ecef, tr.vel_ecef(), tr.quat_nb, tr.omega_ib_b)
    for g, o in ep.obs.items():
        keep(f"{g}/", o)
    for g, o in ep.signal_truth.items():
        keep(f"{g}/", o)
    keep("truth/", ep.truth)
    keep("", ep)
np.savez(sys.argv[3], **{k: np.concatenate(v) for k, v in out.items()})
"""


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a", help="checkout A (e.g. the code before a change)")
    ap.add_argument("b", help="checkout B")
    ap.add_argument("--minutes", type=float, default=15.0)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        files = []
        for tree in (args.a, args.b):
            path = Path(tmp) / f"{len(files)}.npz"
            subprocess.run([sys.executable, "-c", PROBE, str(Path(tree).resolve()), str(HERE), str(path),
                            str(args.minutes)], check=True)
            files.append(np.load(path))
        a, b = files
        same_nan = True
        for key in a.files:
            x, y = a[key], b[key]
            same_nan &= bool(np.array_equal(np.isnan(x), np.isnan(y)))
            diff = np.abs(x - y)
            print(f"{key:32s} max |A - B| {np.nanmax(diff) if np.isfinite(diff).any() else 0.0:.2e}")
        print(f"NaN patterns {'identical' if same_nan else 'DIFFER'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
