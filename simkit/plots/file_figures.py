"""The overview figures of a simkit file (``simkit plot FILE.h5``): one PNG per figure, each made only when the
file holds what it needs (a file without /gnss has no sky plot)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import frames
from ..errors import SimkitError
from ..io import gnss_signals, has, n_samples, open_dataset, read_gnss, read_imu, read_truth, solution_names
from .common import draw, require_matplotlib, skip_line

MAX_POINTS = 20_000        # truth samples drawn per curve (strided beyond that)
MAX_EPOCHS = 2_000         # GNSS epochs drawn per satellite
MAX_ALLAN = 1 << 22        # IMU samples analysed (4.2 M: 11.6 h at 100 Hz), bounded memory on long files


def _stride(n: int, limit: int) -> int:
    return max(1, -(-n // limit))


def _every(ds) -> slice:
    """The GNSS epochs drawn: every k-th, at most MAX_EPOCHS."""
    return slice(None, None, _stride(n_samples(ds, "gnss"), MAX_EPOCHS))


def _trajectory(plt, ds):
    if not has(ds, "truth", "pos_lla"):
        return None
    k = _stride(n_samples(ds, "truth"), MAX_POINTS)
    tr = read_truth(ds, fields=("pos_lla", "pos_ecef"), required=("pos_lla", "pos_ecef"), epochs=slice(None, None, k))
    t, lla = tr.t, tr.pos_lla
    enu = frames.ecef_to_enu_vec(tr.pos_ecef - tr.pos_ecef[0], lla[0, 0], lla[0, 1])
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.5), gridspec_kw={"width_ratios": [1.2, 1]})
    a.plot(enu[:, 0] / 1e3, enu[:, 1] / 1e3, lw=1, label="truth")
    a.plot(enu[0, 0] / 1e3, enu[0, 1] / 1e3, "go", label="start")
    a.plot(enu[-1, 0] / 1e3, enu[-1, 1] / 1e3, "rs", label="end")
    a.set_xlabel("east of start [km]")
    a.set_ylabel("north of start [km]")
    a.set_aspect("equal", adjustable="datalim")
    a.set_title(f"trajectory map (origin {np.degrees(lla[0, 0]):.4f} N, {np.degrees(lla[0, 1]):.4f} E)")
    b.plot(t, lla[:, 2], lw=1, label="ellipsoidal height")
    b.set_xlabel("time since scenario start [s]")
    b.set_ylabel("height [m]")
    b.set_title("altitude")
    for ax in (a, b):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    return fig


STATE_STYLE = {1: ("^", "tab:orange", "direct + reflection"), 2: ("o", "tab:purple", "reflection only (NLOS)"),
               3: ("x", "0.5", "blocked")}


def _sky(plt, ds):
    if not has(ds, "gnss_truth", "elevation"):
        return None
    with_los = has(ds, "gnss_truth", "los_state")
    g = read_gnss(ds, signals=(), antennas=0, epochs=_every(ds),
                  truth=("elevation", "azimuth") + (("los_state",) if with_los else ()), satellites=False)
    el, az = g.truth["elevation"], g.truth["azimuth"]
    state = g.truth["los_state"] if with_los else np.zeros(el.shape, dtype=np.uint8)
    ids = [str(s) for s in g.sat_id]
    fig = plt.figure(figsize=(6.5, 6.5))
    ax = fig.add_subplot(projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    seen = set()
    for s in np.flatnonzero(np.any(el > 0, axis=0)):
        up = el[:, s] > 0
        system = ids[s][0]
        color = {"G": "tab:blue", "C": "tab:red"}.get(system, "tab:gray")
        direct = up & (state[:, s] == 0)
        ax.plot(az[direct, s], 90 - np.degrees(el[direct, s]), ".", ms=2, color=color,
                label={"G": "GPS", "C": "BeiDou"}.get(system, system) if system not in seen else None)
        seen.add(system)
        for code, (marker, colour, name) in STATE_STYLE.items():
            sel = up & (state[:, s] == code)
            ax.plot(az[sel, s], 90 - np.degrees(el[sel, s]), marker, ms=3, color=colour, mfc="none",
                    label=name if name not in seen and sel.any() else None)
            seen.add(name) if sel.any() else None
        k = np.flatnonzero(up)[-1]
        ax.annotate(ids[s], (az[k, s], 90 - np.degrees(el[k, s])), fontsize=7)
    ax.set_ylim(0, 90)
    ax.set_yticks([0, 30, 60, 90], labels=["90 deg", "60 deg", "30 deg", "0 deg"])
    ax.set_title("sky plot, antenna 0 (azimuth clockwise from north, elevation in deg)"
                 + ("\ndots: direct line of sight; other marks: the environment's states" if with_los else ""))
    ax.legend(loc="lower left", fontsize=8)
    return fig


def _line_of_sight(plt, ds):
    """Per-epoch counts of each line-of-sight state above the horizon, one panel per antenna."""
    if not has(ds, "gnss_truth", "los_state"):
        return None
    g = read_gnss(ds, signals=(), epochs=_every(ds), truth=("los_state",), satellites=False)
    state = g.truth["los_state"]                                             # (M, A, S)
    n_ant = state.shape[1]
    fig, axes = plt.subplots(n_ant, 1, figsize=(8, 2.6 * n_ant + 0.6), sharex=True, squeeze=False,
                             layout="constrained")
    for a, ax in enumerate(axes[:, 0]):
        ax.step(g.t, (state[:, a] == 0).sum(axis=1), where="post", color="tab:green", label="direct")
        for code, (_, colour, name) in STATE_STYLE.items():
            ax.step(g.t, (state[:, a] == code).sum(axis=1), where="post", color=colour, label=name)
        ax.set_ylabel("satellites [count]")
        ax.set_title(f"line-of-sight states above the horizon, antenna {a}")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")
    axes[-1, 0].set_xlabel("time since scenario start [s]")
    return fig


def _dops(plt, ds):
    if not has(ds, "gnss_truth", "elevation"):
        return None
    from ..constellation import dops

    g = read_gnss(ds, antennas=0, epochs=_every(ds), obs=("code",), truth=("elevation", "azimuth"), satellites=False)
    t, el, az = g.t, g.truth["elevation"], g.truth["azimuth"]
    tracked = np.any([np.isfinite(g.obs["code"][s]) for s in g.signals], axis=0)
    system = np.array([str(s)[0] for s in g.sat_id])
    d = dops(np.where(tracked, el, np.nan), az, 0.0, system)
    fig, (a, b) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, layout="constrained")
    for code, name in (("G", "GPS"), ("C", "BeiDou")):
        if np.any(system == code):
            a.step(t, (tracked & (system == code)).sum(axis=1), where="post", label=name)
    a.step(t, tracked.sum(axis=1), where="post", color="k", label="all")
    a.set_ylabel("tracked satellites [count]")
    a.set_title("satellites tracked on any signal, antenna 0")
    for key in "GPHV":
        b.plot(t, d[key], label=f"{key}DOP")
    b.set_ylabel("DOP [1]")
    b.set_xlabel("time since scenario start [s]")
    for ax in (a, b):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")
    return fig


def _allan(plt, ds):
    if not has(ds, "imu", "gyro") or not has(ds, "truth", "omega_ib_b") or n_samples(ds, "imu") < 100:
        return None
    from ..imu.allan import adev

    dt = 1.0 / ds.rate_hz("imu")
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), layout="constrained")
    for ax, (name, truth, unit, scale) in zip(axes, (("gyro", "omega_ib_b", "deg/h", 180 / np.pi * 3600),
                                                      ("accel", "f_ib_b", "m/s^2", 1.0))):
        n = min(n_samples(ds, "imu"), MAX_ALLAN)
        measured = getattr(read_imu(ds, fields=(name,), epochs=slice(0, n)), name)
        taus, dev, _ = adev(measured - getattr(read_truth(ds, fields=(truth,), required=(truth,),
                                                          epochs=slice(0, n)), truth), dt)
        for a, axis in enumerate("xyz"):
            ax.loglog(taus, dev[:, a] * scale, ".-", ms=3, label=f"{axis} axis")
        ax.set_xlabel("averaging time tau [s]")
        ax.set_ylabel(f"Allan deviation [{unit}]")
        ax.set_title(f"{name} error (measured - truth), first {n * dt:.0f} s")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    return fig


def _observations(plt, ds):
    signals = gnss_signals(ds)
    if not signals or not has(ds, "gnss_truth", f"{signals[0]}/noise_code"):
        return None
    terms = [f"{s}/{e}_{kind}" for s in signals for e in ("noise", "multipath") for kind in ("code", "carrier")]
    g = read_gnss(ds, antennas=0, epochs=_every(ds), obs=("code", "carrier"), truth=terms, satellites=False)
    t = g.t
    fig, axes = plt.subplots(len(signals), 2, figsize=(11, 3.2 * len(signals)), squeeze=False, layout="constrained")
    for row, sig in zip(axes, signals):
        for ax, kind in zip(row, ("code", "carrier")):
            err = g.truth[f"{sig}/noise_{kind}"] + g.truth[f"{sig}/multipath_{kind}"]
            err = np.where(np.isfinite(g.obs[kind][sig]), err, np.nan)
            ax.plot(t, err * (1.0 if kind == "code" else 1e3), ".", ms=2)
            ax.plot([], [], ".", label="one colour per satellite")
            ax.set_ylabel(f"{sig} {kind} [{'m' if kind == 'code' else 'mm'}]")
            ax.set_title(f"{sig} {kind}: noise + multipath, antenna 0")
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=8, loc="upper right")
    for ax in axes[-1]:
        ax.set_xlabel("time since scenario start [s]")
    return fig


FIGURES = {"trajectory": _trajectory, "sky": _sky, "satellites_dop": _dops, "imu_allan": _allan,
           "observation_errors": _observations, "line_of_sight": _line_of_sight}


def file_figures(path, out, progress=None, on_skip=skip_line) -> list[Path]:
    """Write every overview figure that ``path`` has the data for, plus one error figure set per stored
    solution (under ``out/solution_<name>/``); returns the PNG paths. A figure or solution that cannot be drawn
    is left out with one line to ``on_skip``. ``progress`` (a tqdm bar) advances once per overview figure and
    once per solution drawn."""
    plt = require_matplotlib()
    out = Path(out)
    paths = []
    with open_dataset(path) as ds:
        for name, make in FIGURES.items():
            paths.append(draw(plt, out / f"{name}.png", make, ds, on_skip=on_skip))
            if progress is not None:
                progress.update(1)
    return [p for p in paths if p is not None] + _solutions(path, out, on_skip, progress)


def _solutions(path, out, on_skip, progress=None) -> list[Path]:
    """The score figures of every stored solution against the truth at its own point."""
    from ..io import read_solution
    from ..referee import read_truth, score
    from .score_figures import score_figures

    paths = []
    names = solution_names(path)
    if not names:
        return paths
    try:
        truth = read_truth(path)
    except SimkitError as exc:  # a real file without a reference position: nothing to score the solutions against
        on_skip(f"plot: skipped the figures of {', '.join(f'/solutions/{n}' for n in names)}: {exc}")
        return paths
    for name in names:
        try:
            sc = score(truth, read_solution(path, name), where=f"/solutions/{name}")
        except SimkitError as exc:
            on_skip(f"plot: skipped /solutions/{name}: {exc}")
            continue
        folder = out / f"solution_{name}"
        folder.mkdir(exist_ok=True)
        paths += score_figures(sc, folder, f"/solutions/{name}", on_skip)
        if progress is not None:
            progress.update(1)
    return paths
