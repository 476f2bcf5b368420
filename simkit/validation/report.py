"""The ``simkit validate`` outputs: JSON (the summary as is) and a Markdown report that shows the PNG figures of
:func:`simkit.plots.validation_figures` (Wang 2018 Figs 2-5)."""
from __future__ import annotations

import json

import numpy as np

from ..atomic import atomic_open


def write_json(path, summary: dict) -> None:
    """``summary`` as indented JSON at ``path`` (written under a temporary name, then renamed)."""
    text = json.dumps(summary, indent=1, allow_nan=False, default=_jsonable).encode()
    with atomic_open(path, "wb") as f:
        f.write(text)


def _jsonable(x):
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, float) and not np.isfinite(x):
        return None
    raise TypeError(f"not JSON: {type(x)}")


def _pct(x) -> str:
    return "n/a" if x is None else f"{100 * x:.2f} %"


def markdown(v, figures: list[str], command: str = "") -> str:
    """The report text: setup, claims table, ranks per satellite count, degenerate geometry, C6/C7 per count,
    counter-examples, figures."""
    s = v.summary
    out = [f"# Observability validation: {s['source']}", ""]
    if command:
        out += [f"Produced by `{command}` (simkit {s['simkit_version']}, {s['elapsed_s']} s).", ""]
    out += _setup(s) + _claims_table(s) + _ranks(s) + _empirical_tables(s) + _examples(s)
    if figures:
        out += ["## Figures", ""] + [f"![{f}]({f})" for f in figures] + [""]
    return "\n".join(out)


def _setup(s) -> list[str]:
    lines = ["## Setup", "", f"- start {s['start_utc']} (GPS week {s['start_gps']['week']}, sow "
             f"{s['start_gps']['sow']:g}), {s['epochs']} epochs every {s['interval_s']:g} s",
             f"- satellites: {len(s['satellites'])} in the sky, {s['visible']['min']}-{s['visible']['max']} visible",
             f"- noise model (R): `{s['weighting']}`; subsets: highest elevation first, plus "
             f"{s['subsets']['random_orderings']} random ordering(s) every {s['subsets']['random_stride']} epochs "
             f"(seed {s['subsets']['seed']})",
             f"- tolerances: rank {s['tolerances']['rank_rtol']:g} x sigma_max; degenerate geometry within "
             f"{s['tolerances']['degeneracy_rad']:g} rad"]
    for name, c in s["configurations"].items():
        lines.append(f"- {name}: baselines (body, m) {c['baselines_b_m']}, lengths {c['lengths_m']} m")
    return lines + [""]


def _claims_table(s) -> list[str]:
    lines = ["## Claims", "", "| claim | type | statement | checked | result |", "|---|---|---|---|---|"]
    for name, c in s["claims"].items():
        if c["type"] == "mathematical":
            res = ("held" if c["held"] else f"**FAILED {c['failed']}**") + f" ({c['degenerate']} degenerate rows aside)"
            n = c["checked"]
        else:
            n = c.get("checked", c.get("comparable"))
            res = f"held in {_pct(c['fraction'])}"
        lines.append(f"| {name} | {c['type']} | {c['statement']} | {n:,} | {res} |")
    return lines + [""]


def _ranks(s) -> list[str]:
    lines = ["## Rank of L per satellite count (non-degenerate epochs; rank: epochs)", ""]
    for group, per_k in s["ranks"].items():
        cells = "; ".join(f"k={k}: " + ", ".join(f"rank {r}: {n}" for r, n in d.items()) for k, d in per_k.items())
        lines.append(f"- {group}: {cells}")
    lines += ["", "Degenerate geometry (excluded from C1-C5, reported here):", ""]
    for group, reasons in s["degenerate"].items():
        lines.append(f"- {group}: " + (", ".join(f"{r}: {n}" for r, n in reasons.items()) or "none"))
    return lines + [""]


def _empirical_tables(s) -> list[str]:
    lines = []
    for name in ("C6", "C7", "C7_all_visible"):
        c = s["claims"][name]
        lines += [f"## {name} per satellite count", "", c["statement"], "", "| group | k | held / checked | fraction |",
                  "|---|---|---|---|"]
        for group, d in c["by"].items():
            for k, val in d["per_k"].items():
                n, h = (val if isinstance(val, list) else [sum(x[0] for x in val.values()),
                                                            sum(x[1] for x in val.values())])
                lines.append(f"| {group} | {k} | {h:,} / {n:,} | {_pct(h / n if n else None)} |")
        lines.append("")
    return lines


def _examples(s) -> list[str]:
    lines = ["## Counter-examples", ""]
    for name, c in s["claims"].items():
        for e in c["counterexamples"]:
            lines.append(f"- {name}: " + json.dumps(e, default=_jsonable))
    if len(lines) == 2:
        lines.append("none")
    return lines + [""]
