"""Score an estimate against the truth: errors, statistics, convergence, NEES / NIS, pass/fail checks."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..solution import Solution
from . import stats
from .compare import Errors, compare
from .line_of_sight import by_state
from .spec import Spec
from .truth import Truth


@dataclass(frozen=True)
class Score:
    """The result of :func:`score`: ``errors`` (per epoch); ``statistics`` {quantity: {stat: value}} in the units
    of ``stats.UNIT_OF``; ``convergence`` {quantity: {threshold, time_s}}; ``nees`` / ``nis`` (dicts with
    ``series``) or None; ``checks`` [{name, value, limit, passed}]; ``meta`` (epochs scored and dropped);
    ``sigmas`` {covariance state name: (K,) standard deviation at the scored epochs, SI}."""

    errors: Errors
    statistics: dict
    convergence: dict
    nees: dict | None
    nis: dict | None
    checks: list = field(default_factory=list)
    meta: dict = field(default_factory=dict)
    bands: dict = field(default_factory=dict)
    by_state: dict = field(default_factory=dict)   # errors per line-of-sight class (simkit.referee.line_of_sight)

    @property
    def passed(self) -> bool:
        """True when no check failed (also when there is no check: see ``checks``)."""
        return all(c["passed"] for c in self.checks)

    def as_dict(self) -> dict:
        """JSON-ready summary (no per-epoch series)."""
        strip = (lambda d: None if d is None else {k: v for k, v in d.items() if k not in ("series", "dof")})
        return {"meta": self.meta, "units": {q: stats.UNIT_OF[q] for q in self.statistics},
                "statistics": self.statistics, "convergence": self.convergence, "nees": strip(self.nees),
                "nis": strip(self.nis), "checks": self.checks, "passed": self.passed,
                **({"by_line_of_sight": self.by_state} if self.by_state else {})}


def score(truth: Truth, sol: Solution, spec: Spec | None = None, where: str = "estimate", path=None) -> Score:
    """Score ``sol`` against ``truth`` (see :mod:`simkit.referee.stats` for quantities and tests) and check it
    against ``spec`` (no checks without one); ``path``, the simkit file of the truth, adds the statistics per
    line-of-sight class of the epochs when it has them (:mod:`simkit.referee.line_of_sight`)."""
    spec = spec if spec is not None else Spec()
    err = compare(truth, sol, where)
    series = stats.series(err)
    missing = stats.not_estimated(err, series)
    series = {q: x for q, x in series.items() if q not in missing}
    table = {q: stats.statistics(x) for q, x in series.items()}
    conv = {q: {"threshold": thr, "time_s": stats.convergence_time(err.t, series[q], thr)}
            for q, (thr, _) in spec.convergence.items() if q in series}
    confidence = spec.consistency.get("confidence", 0.95)
    nees = stats.nees(err, sol.cov, sol.state_names, confidence) if sol.cov is not None else None
    nis = stats.nis(err, sol.extras, confidence)
    meta = {"epochs_scored": int(err.t.size), "epochs_outside_truth": int(np.size(sol.t) - err.t.size),
            "t_first_s": float(err.t[0]), "t_last_s": float(err.t[-1]), "point": sol.point,
            "not_estimated": missing}
    bands = stats.sigma_bands(err, sol.cov, sol.state_names) if sol.cov is not None else {}
    per_state = by_state(path, err, series) if path is not None else {}
    return Score(err, table, conv, nees, nis, _checks(spec, table, conv, nees, nis), meta, bands, per_state)


def _check(name, value, limit, passed):
    return {"name": name, "value": value, "limit": limit, "passed": bool(passed)}


def _checks(spec: Spec, table, conv, nees, nis) -> list:
    out = []
    for (q, s), limit in spec.limits.items():
        value = table.get(q, {}).get(s)
        unit = stats.UNIT_OF[q]
        # a limit on a quantity the estimate does not provide fails: the spec asked for it
        out.append(_check(f"{q}.{s}_{unit} <= {limit:g}", value, limit, value is not None and value <= limit))
    for q, (thr, limit) in spec.convergence.items():
        if limit is not None:
            value = conv.get(q, {}).get("time_s")
            out.append(_check(f"{q} converged to {thr:g} {stats.UNIT_OF[q]} within {limit:g} s", value, limit,
                              value is not None and value <= limit))
    for key, result in (("nees", nees), ("nis", nis)):
        limit = spec.consistency.get(f"{key}_min_fraction_inside")
        if limit is not None:
            value = None if result is None else result["fraction_inside"]
            out.append(_check(f"{key.upper()} inside its {spec.consistency['confidence']:.0%} chi-square bounds "
                              f"at >= {limit:.0%} of epochs", value, limit, value is not None and value >= limit))
    return out
