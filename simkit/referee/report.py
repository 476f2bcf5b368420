"""Scores as Markdown and JSON, and the estimate loader shared by ``simkit score`` and the plugin runner."""
from __future__ import annotations

import json
import math
from pathlib import Path

from ..io import open_dataset, read_solution, solution_names
from ..solution import Solution
from .errors import RefereeInputError
from .score import Score
from .stats import STATS, UNIT_OF

UNIT_TEXT = {"m": "m", "m_per_s": "m/s", "deg": "deg"}


def file_start(path) -> tuple[int, float]:
    """(GPS week, seconds of week) of a simkit file's first epoch."""
    with open_dataset(path) as ds:
        return int(ds.attrs["start_gps_week"]), float(ds.attrs["start_gps_sow"])


def load_estimate(path, name: str | None = None, start=None, point: str | None = None) -> tuple[Solution, str]:
    """An estimate from a simkit HDF5 file (solution ``name``, or its only one) or a CSV whose position and
    velocity belong to ``point`` (default "imu"; a /solutions group declares its own); returns it and a label."""
    from .csvfile import read_csv

    path = Path(path)
    if path.suffix.lower() == ".csv":
        return read_csv(path, start, point or "imu"), path.name
    if point is not None:
        raise RefereeInputError("--point", f"only for a CSV estimate; {path} is read as HDF5, whose "
                                           f"/solutions group declares its own point")
    names = solution_names(path)
    if name is None:
        if len(names) != 1:
            raise RefereeInputError(path, f"{len(names)} solutions stored ({', '.join(names) or 'none'}): "
                                          f"choose one with --solution NAME")
        name = names[0]
    return read_solution(path, name), f"{path.name}:/solutions/{name}"


def _clean(x):
    """JSON-safe: NaN/inf -> None, recursively."""
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if isinstance(x, dict):
        return {str(k): _clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    return x


def to_json(sc: Score, label: str = "") -> str:
    return json.dumps(_clean({"estimate": label, **sc.as_dict()}), indent=2)


def _fmt(v) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return f"{v:.4g}"


def _consistency_lines(sc: Score) -> list[str]:
    lines = []
    for key, r in (("NEES", sc.nees), ("NIS", sc.nis)):
        if r is None:
            continue
        states = f" over {', '.join(r['states'])}" if "states" in r else ""
        lo, hi = r["epoch_bounds"] or (math.nan, math.nan)
        mlo, mhi = r["mean_bounds"] or (math.nan, math.nan)
        lines.append(f"- {key}{states}: mean {_fmt(r['mean'])} (bounds {_fmt(mlo)} .. {_fmt(mhi)} for the mean of "
                     f"{r['epochs']} epochs); {_fmt(100 * r['fraction_inside'])} % of epochs inside "
                     f"[{_fmt(lo)}, {_fmt(hi)}] ({r['confidence']:.0%} chi-square, {_fmt(r['dof_mean'])} dof)")
    return lines or ["- no covariance or NIS in the estimate: no consistency test"]


def _where(meta: dict) -> str:
    """Where the position / velocity errors are taken, for the report's first lines."""
    if {"position", "velocity"} <= set(meta.get("not_estimated", ())):
        return ""
    return f"; position and velocity in ENU, at the point {meta.get('point', 'imu')!r}"


def _state_lines(sc: Score) -> list[str]:
    """RMS per line-of-sight class of the epochs (files with an [environment])."""
    if not sc.by_state:
        return []
    names = list(sc.by_state)
    out = ["", "## By line-of-sight state", "",
           "Epochs classed by the worst signal tracked: nlos (a reflection only), reflected (a reflection beside "
           "the direct signal), direct. RMS per class; satellites per antenna: direct / direct+reflected / NLOS / "
           "blocked.", "",
           "| quantity | unit | " + " | ".join(f"{n} RMS" for n in names) + " |", "|---|---|" + "---:|" * len(names)]
    for q in sc.statistics:
        out.append(f"| {q} | {UNIT_TEXT[UNIT_OF[q]]} | "
                   + " | ".join(_fmt(sc.by_state[n]["statistics"][q]["rms"]) for n in names) + " |")
    out.append("| epochs | | " + " | ".join(str(sc.by_state[n]["epochs"]) for n in names) + " |")
    out.append("| satellites per antenna | | " + " | ".join(
        " / ".join(f"{v:.1f}" for v in sc.by_state[n]["satellites_per_antenna"].values()) for n in names) + " |")
    return out


def to_markdown(sc: Score, label: str = "", truth: str = "") -> str:
    """A Markdown report: statistics table, convergence, NEES/NIS, checks and the verdict."""
    m = sc.meta
    used = f" {m['truth']}" if "truth" in m else ""
    out = [f"# Score of {label or 'estimate'}", "",
           f"Truth: {truth or '-'}{used}; {m['epochs_scored']} epochs scored from {m['t_first_s']:.2f} s to "
           f"{m['t_last_s']:.2f} s ({m['epochs_outside_truth']} outside the truth span left out). Errors are "
           f"estimate - truth{_where(m)}.", "",
           *([f"Not estimated (left out): {', '.join(m['not_estimated'])}.", ""] if m.get("not_estimated") else []),
           "| quantity | unit | " + " | ".join(STATS) + " |", "|---|---|" + "---:|" * len(STATS)]
    for q, row in sc.statistics.items():
        out.append(f"| {q} | {UNIT_TEXT[UNIT_OF[q]]} | " + " | ".join(_fmt(row[s]) for s in STATS) + " |")
    out += _state_lines(sc)
    out += ["", "## Convergence", ""]
    out += [f"- {q}: |error| <= {c['threshold']:g} {UNIT_TEXT[UNIT_OF[q]]} "
            + (f"for good from {c['time_s']:.2f} s after the first epoch" if c["time_s"] is not None
               else "not reached for good (still exceeded at the last epoch)")
            for q, c in sc.convergence.items()]
    out += ["", "## Consistency", "", *_consistency_lines(sc), "", "## Checks", ""]
    out += [f"- {'PASS' if c['passed'] else 'FAIL'}: {c['name']} (value {_fmt(c['value'])})" for c in sc.checks]
    verdict = ("PASS" if sc.passed else "FAIL") if sc.checks else "no checks (no spec given)"
    out += ["", f"**Verdict: {verdict}**"]
    return "\n".join(out) + "\n"


def write_run_outputs(res, title: str, path, json_path=None, out=None) -> None:
    """Print a plugin run's Markdown score and timing (to ``out``, default stdout); optionally write the score and
    timing as JSON to ``json_path``. (Figures: :func:`simkit.plots.score_figures`.)"""
    import sys

    out = out or sys.stdout
    out.write(to_markdown(res.score, title, str(path)))
    out.write("timing: " + ", ".join(f"{k} {v:.4g}" for k, v in res.timing.items()) + "\n")
    if json_path:
        with open(json_path, "w") as f:
            f.write(json.dumps({"score": json.loads(to_json(res.score)), "timing": res.timing}, indent=2))
