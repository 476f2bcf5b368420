"""Error plots of a :class:`simkit.referee.Score`: position, velocity, attitude errors with +-3 sigma bounds
(when the estimate has a covariance), and NEES/NIS against their chi-square bounds. A part the estimate does not
give has no figure; a component it does not give (the roll of a single baseline) says so in its panel."""
from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.stats import chi2

from .common import draw, require_matplotlib, skip_line

# (figure, series attribute, scale, unit, component labels)
PANELS = (("errors_position", "pos_enu", 1.0, "m", ("east", "north", "up")),
          ("errors_velocity", "vel_enu", 1.0, "m/s", ("east", "north", "up")),
          ("errors_attitude", "euler", 180 / np.pi, "deg", ("pitch", "roll", "heading")))


def _error_figure(plt, sc, panel, label):
    """One error series (estimate - truth) per component, with the covariance's +-3 sigma where it has one
    (``Score.bands``: position and velocity from pos_*/d_lat/dv_* states, Euler angles from the misalignment)."""
    name, attr, scale, unit, comps = panel
    x = getattr(sc.errors, attr)
    if x is None:
        return None
    band = sc.bands.get(attr)
    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True, layout="constrained")
    t = sc.errors.t
    for k, ax in enumerate(axes):
        ax.set_ylabel(f"{comps[k]} [{unit}]")
        ax.grid(True, alpha=0.3)
        if not np.isfinite(x[:, k]).any():
            ax.text(0.5, 0.5, f"{comps[k]}: not estimated", ha="center", va="center", transform=ax.transAxes)
            continue
        ax.plot(t, x[:, k] * scale, lw=0.8, label=f"{comps[k]} error")
        if band is not None and np.isfinite(band[:, k]).any():
            ax.plot(t, 3 * band[:, k] * scale, "r--", lw=0.8, label="+-3 sigma (filter)")
            ax.plot(t, -3 * band[:, k] * scale, "r--", lw=0.8)
        ax.legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time since scenario start [s]")
    axes[0].set_title(f"{label}: {name.split('_')[1]} error (estimate - truth{', ENU' if attr != 'euler' else ''})")
    return fig


def _chi_figure(plt, sc, label):
    tests = [(k, r) for k, r in (("NEES", sc.nees), ("NIS", sc.nis)) if r is not None and r["epochs"] > 0]
    if not tests:
        return None
    fig, axes = plt.subplots(len(tests), 1, figsize=(8, 3 * len(tests)), squeeze=False, layout="constrained")
    for ax, (key, r) in zip(axes[:, 0], tests):
        ax.semilogy(sc.errors.t, r["series"], ".", ms=2, label=key)
        if "dof" in r and np.unique(r["dof"][r["dof"] > 0]).size > 1:   # the dimension varies: bounds per epoch
            dof = np.where(r["dof"] > 0, r["dof"], np.nan)
            q = (1 - r["confidence"]) / 2
            lo, hi = chi2.ppf(q, dof), chi2.ppf(1 - q, dof)
            ax.plot(sc.errors.t, lo, "r--", lw=0.8, label=f"{r['confidence']:.0%} chi-square bounds (per-epoch dof)")
            ax.plot(sc.errors.t, hi, "r--", lw=0.8)
        else:
            lo, hi = r["epoch_bounds"]
            ax.axhline(lo, color="r", ls="--", lw=0.8, label=f"{r['confidence']:.0%} chi-square bounds")
            ax.axhline(hi, color="r", ls="--", lw=0.8)
        ax.set_ylabel(f"{key} [1]")
        ax.set_xlabel("time since scenario start [s]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
        ax.set_title(f"{label}: {key} ({r['dof_mean']:.3g} dof), {100 * r['fraction_inside']:.1f} % inside")
    return fig


def score_figures(sc, out, label: str = "estimate", on_skip=skip_line) -> list[Path]:
    """Write the error figures of score ``sc`` into the directory ``out``; returns the PNG paths. A figure that
    cannot be drawn is left out with one line to ``on_skip``."""
    plt = require_matplotlib()
    out = Path(out)
    made = [draw(plt, out / f"{panel[0]}.png", _error_figure, sc, panel, label, on_skip=on_skip) for panel in PANELS]
    made.append(draw(plt, out / "consistency.png", _chi_figure, sc, label, on_skip=on_skip))
    return [p for p in made if p is not None]
