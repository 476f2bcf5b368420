"""Error plots of a :class:`simkit.referee.Score`: position, velocity, attitude errors with +-3 sigma bounds
(when the estimate has a covariance), and NEES/NIS against their chi-square bounds."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .common import require_matplotlib, save

# (figure, series attribute, scale, unit, component labels, covariance state names)
PANELS = (("errors_position", "pos_enu", 1.0, "m", ("east", "north", "up"), ("pos_e", "pos_n", "pos_u")),
          ("errors_velocity", "vel_enu", 1.0, "m/s", ("east", "north", "up"), ("vel_e", "vel_n", "vel_u")),
          ("errors_attitude", "euler", 180 / np.pi, "deg", ("pitch", "roll", "heading"), ("pitch", "roll", "heading")))
ALIASES = {"pos_u": ("pos_d",), "vel_u": ("vel_d",)}


def sigma(sc, name: str) -> np.ndarray | None:
    """Standard deviation (K,) of the covariance state ``name`` (or its NED alias) at the scored epochs."""
    for candidate in (name, *ALIASES.get(name, ())):
        if candidate in sc.sigmas:
            return sc.sigmas[candidate]
    return None


def _error_figure(plt, sc, panel, label):
    name, attr, scale, unit, comps, states = panel
    x = getattr(sc.errors, attr)
    if x is None:
        return None
    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    t = sc.errors.t
    for k, ax in enumerate(axes):
        ax.plot(t, x[:, k] * scale, lw=0.8, label=f"{comps[k]} error")
        s = sigma(sc, states[k])
        if s is not None:
            ax.plot(t, 3 * s * scale, "r--", lw=0.8, label="+-3 sigma (filter)")
            ax.plot(t, -3 * s * scale, "r--", lw=0.8)
        ax.set_ylabel(f"{comps[k]} [{unit}]")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time since scenario start [s]")
    axes[0].set_title(f"{label}: {name.split('_')[1]} error (estimate - truth{', ENU' if attr != 'euler' else ''})")
    return fig


def _chi_figure(plt, sc, label):
    tests = [(k, r) for k, r in (("NEES", sc.nees), ("NIS", sc.nis)) if r is not None]
    if not tests:
        return None
    fig, axes = plt.subplots(len(tests), 1, figsize=(8, 3 * len(tests)), squeeze=False, layout="constrained")
    for ax, (key, r) in zip(axes[:, 0], tests):
        ax.semilogy(sc.errors.t, r["series"], ".", ms=2, label=key)
        lo, hi = r["epoch_bounds"]
        ax.axhline(lo, color="r", ls="--", lw=0.8, label=f"{r['confidence']:.0%} chi-square bounds")
        ax.axhline(hi, color="r", ls="--", lw=0.8)
        ax.set_ylabel(f"{key} [1]")
        ax.set_xlabel("time since scenario start [s]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
        ax.set_title(f"{label}: {key} ({r['dof_mean']:.3g} dof), {100 * r['fraction_inside']:.1f} % inside")
    return fig


def score_figures(sc, out, label: str = "estimate") -> list[Path]:
    """Write the error figures of score ``sc`` into the directory ``out``; returns the PNG paths."""
    plt = require_matplotlib()
    out = Path(out)
    paths = []
    for panel in PANELS:
        fig = _error_figure(plt, sc, panel, label)
        if fig is not None:
            save(fig, out / f"{panel[0]}.png")
            paths.append(out / f"{panel[0]}.png")
    fig = _chi_figure(plt, sc, label)
    if fig is not None:
        save(fig, out / "consistency.png")
        paths.append(out / "consistency.png")
    return paths
