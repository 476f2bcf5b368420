"""Every array of the observables stage of ``bench_gnss.py`` from two checkouts, compared: the largest absolute
difference per array (code, carrier, Doppler, range, range rate, ionosphere and its rate) and whether the NaN
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
out = {}
for tr in Trajectory(sc.trajectory, sc.duration_s).blocks(rate_hz=sc.gnss.rate_hz, block_samples=300):
    ep = sim.process(tr.t, tr.pos_ecef, tr.vel_ecef(), tr.quat_nb, tr.omega_ib_b)
    for g, o in ep.obs.items():
        for f in ("code", "carrier", "doppler"):
            out.setdefault(f"{g}/{f}", []).append(getattr(o, f))
    for g, o in ep.signal_truth.items():
        for f in ("ionosphere", "ionosphere_rate"):
            out.setdefault(f"{g}/{f}", []).append(getattr(o, f))
    for f in ("range", "range_rate"):
        out.setdefault(f, []).append(getattr(ep.truth, f))
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
            print(f"{key:24s} max |A - B| {np.nanmax(np.abs(x - y)):.2e}")
        print(f"NaN patterns {'identical' if same_nan else 'DIFFER'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
