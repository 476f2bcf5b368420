"""Single-epoch fix and wrong-fix rates per satellite count from a simkit file, beside the bootstrapped
success-rate prediction (issue 12's xian_static_bds table). Validation is off (ratio_threshold = 0): every epoch
is fixed, so fixed-correct / wrong-fix are the empirical success / failure rates of the estimator itself.
"""
from __future__ import annotations

import numpy as np
from scipy.stats import binomtest

from .. import ambiguity as amb
from .dd import float_solution
from .params import AMBIGUITY_DEFAULTS, merge
from .reading import read
from .solvers import SOLVER_NAMES, solver


def fix_table(ds, names=("attitude", "attitude_c", "attitude_mc"), counts=(4, 5, 6, 7, 8, 9, 0), every=30,
              progress=False, n_samples=2000, **params) -> list[dict]:
    """Rows per (estimator, satellite count; 0 = all): epochs, fix rate (correct), wrong-fix rate, searches that hit
    the work cap (``not_finished``: neither), the fix rate's binomial
    95 % interval (Clopper-Pearson), the mean bootstrapped success rate of the same epochs and (LAMBDA) the
    Monte Carlo ILS success rate of :func:`ils_prediction` with ``n_samples`` draws per epoch."""
    rows = []
    for name in names:
        if name not in SOLVER_NAMES:
            raise ValueError(f"names: {name!r}; expected some of {SOLVER_NAMES}")
        for count in counts:
            p = {"ratio_threshold": 0.0, "max_sats": count, "every": every, "continuity": 0, **params}
            sol = solver(name)(ds, p, progress)
            st, n_sats = sol.extras["status"], sol.extras["n_sats"]
            use = (st >= 0) & ((n_sats == count) if count else True)
            k, n, w = int((st[use] == 1).sum()), int(use.sum()), int((st[use] == 3).sum())
            lo, hi = binomtest(k, n).proportion_ci(0.95) if n else (np.nan, np.nan)
            rows.append({"estimator": name, "sats": count or "all", "epochs": n, "fix_rate": k / n if n else np.nan,
                         "wrong_fix_rate": w / n if n else np.nan, "not_finished": n - k - w, "fix_ci95": (lo, hi),
                         "bootstrap_sr": float(np.mean(sol.extras["success_rate"][use])) if n else np.nan,
                         "ils_sr_mc": ils_prediction(ds, count, every, n_samples=n_samples, **params)
                         if name == "attitude" else np.nan})
    return rows


def ils_prediction(ds, count, every=30, n_epochs=60, n_samples=2000, seed=0, **params) -> float:
    """Mean Monte Carlo ILS success rate of ``n_epochs`` epochs spread over the run (``n_samples`` draws each):
    the prediction of the LAMBDA (unconstrained ILS) success rate itself, of which bootstrapping is a lower bound."""
    p = merge(AMBIGUITY_DEFAULTS, {"max_sats": count, "every": every, **params}, "attitude")
    fd = read(ds, p)
    groups = float_solution(fd.obs, np.radians(p["mask_deg"]), p["max_sats"] or None)
    Qs = [(q, len(np.unique(np.concatenate([g.sat, g.ref])))) for g in groups for q in g.Qa]
    Qs = [q for q, n in Qs if not count or n == count]
    if not Qs:
        return np.nan
    rng = np.random.default_rng(seed)
    pick = np.linspace(0, len(Qs) - 1, min(n_epochs, len(Qs))).astype(int)
    return float(np.mean([amb.monte_carlo_success_rate(Qs[i], n_samples, rng)[0] for i in pick]))


def format_table(rows) -> str:
    """Markdown table of :func:`fix_table` rows."""
    out = ["| estimator | satellites | epochs | fix rate | wrong-fix rate | not finished | fix rate 95 % CI | "
           "bootstrapped SR | ILS SR (MC) |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lo, hi = r["fix_ci95"]
        out.append(f"| {r['estimator']} | {r['sats']} | {r['epochs']} | {r['fix_rate']:.4f} | "
                   f"{r['wrong_fix_rate']:.4f} | {r['not_finished']} | {lo:.4f}-{hi:.4f} | {r['bootstrap_sr']:.4f} | "
                   f"{r['ils_sr_mc']:.4f} |")
    return "\n".join(out)
