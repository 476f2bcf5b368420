"""Campaign statistics per grid point from the per-run records.

Metric values are flattened to ``<metric>.<key>``. A pair ``<x>_successes`` / ``<x>_trials`` becomes a rate:
pooled over every trial of every run with its Wilson interval (exact when trials are independent, e.g. epochs
with white noise; optimistic when they are correlated, e.g. multipath over a static day), and the per-run rates
with a Student-t interval of their mean, which treats each run as one independent sample. Every other number
gets n, mean, std, min, max and the Student-t interval of its mean.
"""
from __future__ import annotations

from collections import defaultdict

from .stats import mean_interval, rate


def flatten(metrics: dict) -> dict[str, float]:
    """{metric: {key: v}} -> {"metric.key": v} (numbers only; None stays None)."""
    return {f"{m}.{k}": v for m, values in metrics.items() for k, v in values.items()
            if v is None or isinstance(v, (int, float))}


def _columns(records) -> dict[str, list]:
    cols = defaultdict(list)
    for rec in records:
        for key, v in flatten(rec.get("metrics", {})).items():
            cols[key].append(float("nan") if v is None else float(v))
    return cols


def point_statistics(records, confidence: float = 0.95) -> dict:
    """``rates`` and ``statistics`` of the completed records of one grid point."""
    cols = _columns(records)
    rates, stats = {}, {}
    for key in sorted(cols):
        if key.endswith("_successes") and key[:-10] + "_trials" in cols:
            name = key[:-10]
            k, n = cols[key], cols[name + "_trials"]
            pooled = rate(int(sum(k)), int(sum(n)), confidence)
            pooled["per_run"] = mean_interval([a / b for a, b in zip(k, n) if b > 0], confidence)
            rates[name] = pooled
        elif not (key.endswith("_trials") and key[:-7] + "_successes" in cols):
            stats[key] = mean_interval(cols[key], confidence)
    return {"rates": rates, "statistics": stats}


def summarise(specs, records: dict, confidence: float = 0.95) -> tuple[list, list]:
    """(points, failures): statistics per grid point in plan order, and the failed runs with their errors."""
    by_point = defaultdict(list)
    for spec in specs:
        by_point[spec.point].append(spec)
    points, failures = [], []
    for p, point_specs in sorted(by_point.items()):
        recs = [records.get(s.run_id) for s in point_specs]
        ok = [r for r in recs if r is not None and r.get("status") == "ok"]
        bad = [r for r in recs if r is not None and r.get("status") != "ok"]
        failures += [{"run_id": r["run_id"], "seed": r["seed"], "point": p, "error": r.get("error")} for r in bad]
        entry = {"point": p, "overrides": list(point_specs[0].overrides), "runs": len(point_specs),
                 "completed": len(ok), "failed": len(bad)}
        entry.update(point_statistics(ok, confidence))
        points.append(entry)
    return points, failures


def run_table(specs, records: dict) -> list[dict]:
    """The per-run summary table: id, seed, grid point, status, file, digest, elapsed time, flattened metrics."""
    rows = []
    for spec in specs:
        rec = records.get(spec.run_id) or {}
        rows.append({"run_id": spec.run_id, "seed": spec.seed, "point": spec.point,
                     "status": rec.get("status", "missing"), "file": f"runs/{spec.run_id}.h5",
                     "sha256": rec.get("sha256"), "elapsed_s": rec.get("elapsed_s"),
                     "metrics": flatten(rec.get("metrics", {}))})
    return rows
