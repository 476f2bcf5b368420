"""The figures of ``simkit twin``: real and twin side by side from the fidelity dict (:mod:`simkit.realdata.twin`):
tracked satellites per epoch, C/N0 and code noise against elevation."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .common import require_matplotlib


def _centres(result):
    edges = np.asarray(result["elevation_bins_deg"])
    return 0.5 * (edges[:-1] + edges[1:])


def _curve(ax, x, values, **style):
    y = np.array([np.nan if v is None else v for v in values], float)
    if np.isfinite(y).any():
        ax.plot(x, y, marker="o", **style)


def twin_figures(fid: dict, out_dir) -> list[Path]:
    """Write the PNG figures of a twin's fidelity dict ``fid`` into ``out_dir``; returns their paths."""
    plt = require_matplotlib("twin")
    out_dir = Path(out_dir)
    runs = [k for k in ("default", "fitted") if k in fid]
    paths = []
    base = fid[runs[0]]
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ser = base["tracked_series"]
    ax.step(ser["t"], ser["real"], where="mid", label="real")
    for k in runs:
        ax.step(fid[k]["tracked_series"]["t"], fid[k]["tracked_series"]["twin"], where="mid", ls="--",
                label=f"twin ({k})")
    ax.set_xlabel("time since the first epoch (s)")
    ax.set_ylabel("satellites tracked")
    ax.legend()
    paths.append(_save(plt, fig, out_dir / "tracked.png"))
    x = _centres(base)
    for quantity, unit, name in (("cn0_dbhz", "C/N0 (dB-Hz)", "cn0.png"), ("code_noise_m", "code noise and "
                                 "multipath sigma (m)", "code_noise.png")):
        signals = list(base["real"][quantity])
        if not any(any(v is not None for v in base["real"][quantity][s]) for s in signals):
            continue
        cols = min(4, len(signals))
        rows = -(-len(signals) // cols)
        fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 2.8 * rows), squeeze=False)
        for ax, s in zip(axes.ravel(), signals):
            _curve(ax, x, base["real"][quantity][s], label="real", color="k")
            for k in runs:
                _curve(ax, x, fid[k]["twin"][quantity][s], label=f"twin ({k})", ls="--")
            ax.set_title(s)
            ax.set_xlabel("elevation (deg)")
            ax.set_ylabel(unit)
            if quantity == "code_noise_m":
                ax.set_yscale("log")
        for ax in axes.ravel()[len(signals):]:
            ax.axis("off")
        axes.ravel()[0].legend(fontsize="small")
        paths.append(_save(plt, fig, out_dir / name))
    return paths


def _save(plt, fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
