"""The ``simkit validate`` outputs: JSON (the summary as is) and a Markdown report with PNG figures in the style
of Wang 2018 Figs 2-5 (visible satellites; each ATDOP against its observable degree over the day)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..atomic import atomic_open

ANGLES = (("pitch", "PIDOP"), ("roll", "RDOP"), ("yaw", "YDOP"))
PLOT_STEP_S = 60.0      # one plotted point a minute keeps each PNG near 50 kB


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


def _thin(v):
    step = max(1, int(round(PLOT_STEP_S / max(np.median(np.diff(v.t)) if len(v.t) > 1 else 1.0, 1e-9))))
    return slice(None, None, step)


def plots(folder: Path, v, config: str = "three") -> list[str]:
    """Fig 2 (visible count) and Figs 3-5 (ATDOP and observable degree of each angle) for ``config`` with all
    visible satellites; returns the file names written into ``folder``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    config = config if config in v.series else next(iter(v.series))
    sl = _thin(v)
    hours = v.t[sl] / 3600.0
    names = []
    fig, ax = plt.subplots(figsize=(6.4, 2.6))
    ax.step(v.t / 3600.0, v.visible, where="post", lw=0.8)
    ax.set(xlabel="hours since start", ylabel="visible satellites", title="Visible satellites (cf. Fig. 2)")
    names.append(_save(fig, folder, "fig2_visible.png"))
    atd, deg = v.series[config]
    for a, (angle, dop) in enumerate(ANGLES):
        fig, ax = plt.subplots(figsize=(6.4, 2.6))
        ax.plot(hours, atd[sl, a], lw=0.8, color="tab:blue")
        ax.set(xlabel="hours since start", ylabel=dop, title=f"{dop} and observable degree of {angle} "
               f"({config}, all visible; cf. Fig. {3 + a})")
        ax2 = ax.twinx()
        ax2.plot(hours, deg[sl, a], lw=0.8, color="tab:red")
        ax2.set_ylabel(f"observable degree ({angle})", color="tab:red")
        names.append(_save(fig, folder, f"fig{3 + a}_{angle}.png"))
    return names


def _save(fig, folder: Path, name: str) -> str:
    fig.tight_layout()
    with atomic_open(folder / name, "wb") as f:
        fig.savefig(f, format="png", dpi=72)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return name


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
