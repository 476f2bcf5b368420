"""``validate(geometry)``: run every configuration and subset kind, and gather the claims into one JSON-ready
summary (the ``--json`` output of ``simkit validate``; keys in docs/validation.md)."""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .. import gpstime
from .degeneracy import DEGENERACY_TOL_RAD, REASONS
from .engine import MAX_EXAMPLES, c7, run_group
from .errors import ValidationInputError
from .geometry import every_nth
from .gramian import WEIGHTINGS
from .observability import NULL_COMPONENT_TOL, RANK_RTOL

STATEMENTS = {
    "C1": "Theorem 1: diag(L^-1)_i = sum_j u_ij^2 / sigma_j, ATDOP_i = its square root",
    "C2": "eqs 5, 13-15: observable degree mu_i = sqrt(sum_j sigma_j^2 u_ij^2)",
    "C3": "Theorem 2: rank(H^T R^-1 H) = rank(H^T H) for a nonsingular (covariance) R",
    "C4": "dual antenna: rank(L) = 1 with 2 satellites, 2 with 3 or more",
    "C5": "three antennas: rank(L) = 2 with 2 satellites, 3 with 3 or more",
    "C6": "at an epoch, the angle with the lower ATDOP has the higher observable degree",
    "C7": "one angle, same satellite count: lower ATDOP at one epoch, higher observable degree than at another",
}
MATHEMATICAL = ("C1", "C2", "C3", "C4", "C5")


@dataclass(frozen=True)
class Validation:
    """``summary`` the JSON-ready dict; ``t`` (M,) s, ``visible`` (M,) counts; ``series[config]`` =
    (atdop (M, 3), degree (M, 3)) with all visible satellites (NaN where fewer than 2 or degenerate)."""

    summary: dict
    t: np.ndarray
    visible: np.ndarray
    series: dict

    @property
    def mathematical_failure(self) -> bool:
        return any(not self.summary["claims"][c]["held"] for c in MATHEMATICAL if c in self.summary["claims"])


def _kinds(n_random: int):
    return ["highest"] + [f"random{r + 1}" for r in range(n_random)]


def validate(geo, weighting: str = "dd", n_random: int = 1, seed: int = 0, random_stride: int = 10,
             progress: bool = False) -> Validation:
    """Claims C1-C7 over every epoch of ``geo`` (:class:`~simkit.validation.geometry.ValidationGeometry`), for the dual
    and (with 3+ antennas) three-antenna configurations, every satellite count 2..visible, the highest subsets
    at every epoch and ``n_random`` random orderings drawn from ``seed`` at every ``random_stride``-th epoch
    (at 1 Hz the geometry barely moves in 10 s; 1 = every epoch)."""
    if weighting not in WEIGHTINGS:
        raise ValidationInputError(f"--weighting: expected one of {', '.join(WEIGHTINGS)}, got {weighting!r}")
    if n_random < 0:
        raise ValidationInputError(f"--random: expected a count >= 0, got {n_random}")
    if random_stride < 1:
        raise ValidationInputError(f"--random-stride: expected an epoch step >= 1, got {random_stride}")
    if int(geo.visible.sum(axis=1).max(initial=0)) < 2:
        raise ValidationInputError(f"{geo.source}: fewer than 2 satellites visible at every epoch: nothing to "
                                   "double-difference")
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    configs = geo.configurations()
    sparse = every_nth(geo, random_stride)
    chunks = (-(-len(geo.t) // 8192) + -(-len(sparse.t) // 8192) * n_random) * len(configs)
    bar = _bar(chunks, progress)
    groups, series = [], {}
    for name, baselines in configs.items():
        for kind in _kinds(n_random):
            sub = geo if kind == "highest" else sparse
            g = run_group(sub, name, baselines, kind, weighting, rng, progress=bar)
            g.tallies["C7"] = c7(sub, g)
            if kind == "highest":
                g.tallies["C7all"] = c7(geo, g, all_visible=True)
                series[name] = _all_visible(geo, g)
            groups.append(_slim(g))
    if bar is not None:
        bar.close()
    summary = _summary(geo, configs, groups, weighting, n_random, seed)
    summary["subsets"]["random_stride"] = random_stride
    summary["elapsed_s"] = round(time.perf_counter() - t0, 2)
    return Validation(summary, geo.t, geo.visible.sum(axis=1), series)


def _bar(total, progress):
    if not progress:
        return None
    from tqdm import tqdm

    return tqdm(total=total, desc="validate", unit="chunk")


def _slim(g):
    """What the summary needs of a group (drops the (M, K) arrays)."""
    codes, counts = np.unique(g.code[g.valid], return_counts=True)
    ranks = {}
    for j in range(g.valid.shape[1]):
        rows = g.valid[:, j] & (g.code[:, j] == 0)
        r, n = np.unique(g.rank[rows, j], return_counts=True)
        if n.size:
            ranks[str(j + 2)] = {str(int(a)): int(b) for a, b in zip(r, n)}
    reasons = {REASONS[int(c)]: int(n) for c, n in zip(codes, counts) if c}
    return {"config": g.config, "kind": g.kind, "tallies": g.tallies, "ranks": ranks, "degenerate": reasons}


def _all_visible(geo, g):
    nvis = geo.visible.sum(axis=1)
    j = np.clip(nvis - 2, 0, None)
    m = np.arange(len(nvis))
    ok = (nvis >= 2) & (g.code[m, j] == 0)
    atd = np.where(ok[:, None], g.atdop[m, j], np.nan)
    deg = np.where(ok[:, None], g.degree[m, j], np.nan)
    return atd, deg


def _summary(geo, configs, groups, weighting, n_random, seed) -> dict:
    from ..version import __version__

    nvis = geo.visible.sum(axis=1)
    start = gpstime.gps_to_utc(geo.week, geo.sow0)
    out = {
        "simkit_version": __version__, "source": geo.source, "start_utc": start.strftime("%Y-%m-%dT%H:%M:%SZ"),
        "start_gps": {"week": geo.week, "sow": geo.sow0}, "epochs": int(len(geo.t)),
        "interval_s": float(np.median(np.diff(geo.t))) if len(geo.t) > 1 else 0.0,
        "satellites": list(geo.sat_ids), "visible": {"min": int(nvis.min()), "max": int(nvis.max())},
        "weighting": weighting, "subsets": {"highest": True, "random_orderings": n_random, "seed": seed},
        "tolerances": {"rank_rtol": RANK_RTOL, "degeneracy_rad": DEGENERACY_TOL_RAD,
                       "null_component": NULL_COMPONENT_TOL},
        "configurations": {k: {"baselines_b_m": np.round(v, 6).tolist(),
                               "lengths_m": np.round(np.linalg.norm(v, axis=1), 6).tolist()}
                           for k, v in configs.items()},
        "ranks": {}, "degenerate": {}, "claims": {},
    }
    for g in groups:
        key = f"{g['config']}/{g['kind']}"
        out["ranks"][key] = g["ranks"]
        out["degenerate"][key] = g["degenerate"]
    for claim in MATHEMATICAL:
        _math_claim(out, claim, groups)
    _empirical(out, "C6", groups, "C6", "checked", "held")
    _empirical(out, "C7", groups, "C7", "comparable", "held")
    _empirical(out, "C7_all_visible", groups, "C7all", "comparable", "held")
    return out


def _math_claim(out, claim, groups):
    tot = {"checked": 0, "failed": 0, "degenerate": 0}
    by, examples = {}, []
    for g in groups:
        t = g["tallies"].get(claim)
        if t is None:
            continue
        for k in tot:
            tot[k] += t[k]
        by[f"{g['config']}/{g['kind']}"] = {k: t[k] for k in tot}
        examples += [dict(e, group=f"{g['config']}/{g['kind']}") for e in t["examples"]]
    out["claims"][claim] = {"type": "mathematical", "statement": STATEMENTS[claim], "held": tot["failed"] == 0,
                            **tot, "by": by, "counterexamples": examples[:MAX_EXAMPLES]}


def _empirical(out, name, groups, key, n_key, held_key):
    tot_n = tot_h = 0
    by, examples = {}, []
    for g in groups:
        t = g["tallies"].get(key)
        if t is None:
            continue
        tot_n += t[n_key]
        tot_h += t[held_key]
        label = f"{g['config']}/{g['kind']}"
        by[label] = {n_key: t[n_key], "held": t[held_key], "fraction": t[held_key] / t[n_key] if t[n_key] else None,
                     "per_k": {str(k): v for k, v in t["per_k"].items()}}
        examples += [dict(e, group=label) for e in t["examples"][:2]]
    claim = STATEMENTS["C7" if name.startswith("C7") else name]
    if name == "C7_all_visible":
        claim += " (epochs grouped by their visible count, all visible satellites: the paper's setting)"
    out["claims"][name] = {"type": "empirical", "statement": claim, n_key: tot_n, "held": tot_h,
                           "fraction": tot_h / tot_n if tot_n else None, "by": by, "counterexamples": examples}
