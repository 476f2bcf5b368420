"""Fix rate of LAMBDA against the number of epochs in the float solution (several epochs, docs/attitude.md).

``python -m studies.attitude_float FILE [--counts 5,6] [--windows 1,2,5,10] [--every 30] [--static]``
prints a markdown table: per satellite count and window length N, the single-shot LAMBDA (ILS, no validation)
fix and wrong-fix rates at every ``every``-th epoch (each float over the N epochs ending there) beside the mean
bootstrapped success rate of the same floats. The floats treat the noise as white in time; the simulator's
multipath is a Gauss-Markov process (30 s by default), so the bootstrapped rate overstates what N buys.
"""
from __future__ import annotations

import argparse

import numpy as np
from scipy.stats import binomtest

from simkit.attitude.dd import float_solution
from simkit.attitude.params import AMBIGUITY_DEFAULTS, merge
from simkit.attitude.reading import read
from simkit.attitude.resolve import FixPolicy, resolve, subset
from simkit.attitude.solvers import _wrong, body_baselines


def window_rates(fd, count: int, windows, every: int = 30, static: bool = False, mask_deg: float = 10.0) -> list:
    """Rows {sats, epochs N, n, fix_rate, wrong_rate, fix_ci95, bootstrap_sr} of ``fd`` (a
    :class:`~simkit.attitude.reading.FileData` read at every epoch) with ``count`` satellites."""
    F = body_baselines(fd.lever_arm)
    rows = []
    for n in windows:
        right = wrong = total = 0
        srs = []
        for grp in float_solution(fd.obs, np.radians(mask_deg), count, n, static, fd.lli):
            if len(np.unique(np.concatenate([grp.sat, grp.ref]))) != count:
                continue
            idx = np.flatnonzero(grp.epochs % every == 0)
            if idx.size == 0:
                continue
            sub = subset(grp, idx)
            res = resolve(sub, "lambda", F, FixPolicy(ratio_threshold=0.0, validation="none"))
            bad, _ = _wrong(sub, res, fd)
            ok = res.accepted
            right += int((ok & ~bad).sum())
            wrong += int((ok & bad).sum())
            total += idx.size
            srs.append(res.success_rate)
        lo, hi = binomtest(right, total).proportion_ci(0.95) if total else (np.nan, np.nan)
        rows.append({"sats": count, "epochs": n, "n": total, "fix_rate": right / total if total else np.nan,
                     "wrong_rate": wrong / total if total else np.nan, "fix_ci95": (lo, hi),
                     "bootstrap_sr": float(np.mean(np.concatenate(srs))) if srs else np.nan})
    return rows


def table(ds, counts=(5, 6), windows=(1, 2, 5, 10), every: int = 30, static: bool = False) -> list:
    """:func:`window_rates` of a simkit file for each satellite count."""
    fd = read(ds, merge(AMBIGUITY_DEFAULTS, {}, "attitude"))
    return [row for c in counts for row in window_rates(fd, c, windows, every, static)]


def format_rows(rows) -> str:
    out = ["| satellites | float epochs N | epochs | fix rate | wrong-fix rate | fix rate 95 % CI | bootstrapped SR |",
           "|---|---|---|---|---|---|---|"]
    for r in rows:
        lo, hi = r["fix_ci95"]
        out.append(f"| {r['sats']} | {r['epochs']} | {r['n']} | {r['fix_rate']:.4f} | {r['wrong_rate']:.4f} | "
                   f"{lo:.4f}-{hi:.4f} | {r['bootstrap_sr']:.4f} |")
    return "\n".join(out)


def main(argv=None):
    from simkit.io import open_dataset
    p = argparse.ArgumentParser(prog="python -m studies.attitude_float", description=__doc__.splitlines()[0])
    p.add_argument("file")
    p.add_argument("--counts", default="5,6")
    p.add_argument("--windows", default="1,2,5,10")
    p.add_argument("--every", type=int, default=30)
    p.add_argument("--static", action="store_true", help="one baseline over the window")
    a = p.parse_args(argv)
    with open_dataset(a.file) as ds:
        rows = table(ds, tuple(int(x) for x in a.counts.split(",")), tuple(int(x) for x in a.windows.split(",")),
                     a.every, a.static)
    print(format_rows(rows))


if __name__ == "__main__":
    main()
