"""The figures of single commands: ``simkit allan --plot`` (Allan deviation and its fit), ``simkit sky --plot``
(sky plot) and ``simkit validate --report`` (Wang 2018 Figs 2-5: visible satellites; each ATDOP against its
observable degree over the day). Each is written under a temporary name and renamed (never a partial image).
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from ..atomic import atomic_open
from .common import require_matplotlib

VALIDATION_ANGLES = (("pitch", "PIDOP"), ("roll", "RDOP"), ("yaw", "YDOP"))
VALIDATION_STEP_S = 60.0      # one plotted point a minute keeps each validation PNG near 50 kB
SYSTEM_COLOURS = {"G": ("tab:blue", "GPS"), "C": ("tab:red", "BeiDou")}


def _write(plt, fig, path, kind: str = "png", dpi: int = 120) -> None:
    """``fig`` saved atomically as ``kind`` at ``path``, then released."""
    with atomic_open(path, "wb") as f:
        fig.savefig(f, format=kind, dpi=dpi, bbox_inches="tight")
    plt.close(fig)


def allan_figure(path, taus, dev, fits, sensor: str, unit: str) -> None:
    """Measured overlapping ADEV ``dev`` (T, 3) at ``taus`` (T,) s, in ``unit``, and each axis' fitted curve
    (``fits[axis].adev(taus)``), log-log, as the image ``path`` (type from its extension)."""
    plt = require_matplotlib("--plot")
    fig, ax = plt.subplots(figsize=(7, 5))
    for a, axis in enumerate("xyz"):
        line, = ax.loglog(taus, dev[:, a], ".", label=f"{axis} measured")
        ax.loglog(taus, fits[axis].adev(taus), "-", color=line.get_color(), label=f"{axis} fit")
    ax.set_xlabel("averaging time tau [s]")
    ax.set_ylabel(f"Allan deviation [{unit}]")
    ax.set_title(f"{sensor}: overlapping Allan deviation")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    _write(plt, fig, path, Path(path).suffix.lstrip(".").lower())


STATE_MARKS = {1: ("^", "tab:orange", "direct + reflection"), 2: ("o", "tab:purple", "NLOS (reflection only)"),
               3: ("x", "0.5", "blocked")}


def sky_figure(path, kind: str, const, geo, vis, title: str, states=None) -> None:
    """Polar sky plot of the visible tracks: azimuth clockwise from north, radius elevation (deg); ``geo`` the
    constellation geometry (azimuth, elevation in rad, (T, S)), ``vis`` (T, S) the visible mask; ``states``
    (T, S) line-of-sight states (``simkit.environment``), when given, mark the reflected, NLOS and blocked
    points."""
    plt = require_matplotlib("--plot")
    fig = plt.figure(figsize=(8, 7), layout="constrained")
    ax = fig.add_subplot(projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.set_rlim(90, 0)
    for s, sid in enumerate(const.sat_ids):
        ok = vis[:, s]
        if not ok.any():
            continue
        az, el = geo.azimuth[ok, s], np.degrees(geo.elevation[ok, s])
        st = np.zeros(az.size, dtype=int) if states is None else states[ok, s]
        ax.plot(az[st == 0], el[st == 0], ".", ms=3, color=SYSTEM_COLOURS.get(sid[0], ("k",))[0])
        for code, (marker, colour, _) in STATE_MARKS.items():
            ax.plot(az[st == code], el[st == code], marker, ms=3, color=colour, mfc="none")
        ax.annotate(f"{sid} {const.orbit_type[s][0]}", (az[-1], el[-1]), fontsize=7)
    for system, (colour, name) in SYSTEM_COLOURS.items():   # one legend entry per system drawn
        if any(sid[0] == system and vis[:, s].any() for s, sid in enumerate(const.sat_ids)):
            ax.plot([], [], ".", ms=6, color=colour, label=name)
    for code, (marker, colour, name) in STATE_MARKS.items():
        if states is not None and (vis & (states == code)).any():
            ax.plot([], [], marker, ms=6, color=colour, mfc="none", label=name)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="upper left", bbox_to_anchor=(0.98, 1.0), fontsize=8,
                  title="labels: PRN, orbit\n(M MEO, I IGSO, G GEO)", title_fontsize=7)
    # a long source path would run off the figure: wrap it
    ax.set_title(textwrap.fill(title, 70) + "\nazimuth clockwise from north, radius elevation [deg]", fontsize=9,
                 pad=14)
    _write(plt, fig, path, kind)


def _thin(t) -> slice:
    """Every n-th epoch of ``t`` (s), n giving about one point per :data:`VALIDATION_STEP_S`."""
    dt = np.median(np.diff(t)) if len(t) > 1 else 1.0
    return slice(None, None, max(1, int(round(VALIDATION_STEP_S / max(dt, 1e-9)))))


def validation_figures(folder: Path, v, config: str = "three") -> list[str]:
    """Fig 2 (visible count) and Figs 3-5 (ATDOP and observable degree of each angle) of a validation result
    ``v`` (:mod:`simkit.validation`) for ``config`` with all visible satellites; returns the PNG names written
    into ``folder``."""
    plt = require_matplotlib("--report")
    config = config if config in v.series else next(iter(v.series))
    sl = _thin(v.t)
    hours = v.t[sl] / 3600.0
    fig, ax = plt.subplots(figsize=(6.4, 2.6))
    ax.step(v.t / 3600.0, v.visible, where="post", lw=0.8)
    ax.set(xlabel="hours since start", ylabel="visible satellites", title="Visible satellites (cf. Fig. 2)")
    names = ["fig2_visible.png"]
    _write(plt, fig, folder / names[-1], dpi=72)
    atd, deg = v.series[config]
    for a, (angle, dop) in enumerate(VALIDATION_ANGLES):
        fig, ax = plt.subplots(figsize=(6.4, 2.6))
        ax.plot(hours, atd[sl, a], lw=0.8, color="tab:blue")
        ax.set(xlabel="hours since start", ylabel=dop, title=f"{dop} and observable degree of {angle} "
               f"({config}, all visible; cf. Fig. {3 + a})")
        ax2 = ax.twinx()
        ax2.plot(hours, deg[sl, a], lw=0.8, color="tab:red")
        ax2.set_ylabel(f"observable degree ({angle})", color="tab:red")
        names.append(f"fig{3 + a}_{angle}.png")
        _write(plt, fig, folder / names[-1], dpi=72)
    return names
