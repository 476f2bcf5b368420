"""The figures of docs/estimators.md, each one command: ``python -m studies.estimators NAME [options]``.

``drift FILE [--seconds S]``      strapdown on the error-free truth rates of FILE vs the truth
``badshah FILE [--plot OUT.png]`` kf21 with / without the GNSS attitude, 10 deg initial heading error
``wu [--runs N] [--white]``       KF vs H-infinity RMS per axis on high_dynamic with unmodelled coloured IMU noise
                                  (--white: the preset's own white noise and biases, which the filters model)
``pyins FILE``                    simkit kf15 and pyins' feedback filter on the same data (needs python-ins)
``spp FILE``                      SPP antenna position error (mean, RMS per ENU axis) without / with the broadcast
                                  ionospheric correction
Every study reads simkit files and prints JSON; nothing here is used by the filters themselves.
"""
from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from simkit.frames import ecef_to_enu_vec, ecef_to_lla
from simkit.io import open_dataset
from simkit.estimators.registry import SOLVERS
from simkit.estimators.strapdown import strapdown
from studies.evaluate import errors_vs_truth, rms_table

WU_COLOURED = ["imu.gyro.gauss_markov=[{sigma_deg_per_h=0.5, tau_s=20.0}]",
               "imu.accel.gauss_markov=[{sigma_ug=200.0, tau_s=20.0}]"]
WU_GNSS = {"gnss": "truth", "truth_pos_sigma_m": [0.1, 0.1, 0.1], "truth_vel_sigma_m_per_s": 0.01}


def drift(path, seconds=None) -> dict:
    with open_dataset(path) as ds:
        t = ds["truth/t"][:]
        n = t.size if seconds is None else min(t.size, int(np.searchsorted(t, seconds + 1e-9)) + 1)
        sol = strapdown(t[:n], ds["truth/omega_ib_b"][:n], ds["truth/f_ib_b"][:n],
                        pos0_lla=ds["truth/pos_lla"][0], vel0_enu=ds["truth/vel_enu"][0],
                        quat0_nb=ds["truth/quat_nb"][0])
        lla = ds["truth/pos_lla"][:n]
        dp = ecef_to_enu_vec(sol.pos_ecef - ds["truth/pos_ecef"][:n], lla[:, 0], lla[:, 1])
        dv = sol.vel_enu - ds["truth/vel_enu"][:n]
        da = (Rotation.from_quat(sol.quat_nb) * Rotation.from_quat(ds["truth/quat_nb"][:n]).inv()).magnitude()
        rate = ds.rate_hz("truth")
    return {"file": str(path), "seconds": float(t[n - 1] - t[0]), "rate_hz": rate,
            "max_pos_err_m": float(np.linalg.norm(dp, axis=1).max()),
            "max_vel_err_m_per_s": float(np.linalg.norm(dv, axis=1).max()),
            "max_att_err_rad": float(da.max())}


def badshah(path, plot=None, heading_error_deg=10.0) -> dict:
    """kf21 on ``path`` (airborne_stim300) from the truth attitude plus a heading error, with Badshah's GNSS
    accuracies (position [1, 1, 5] m, velocity 0.5 cm/s, attitude 0.3 deg), with and without the attitude."""
    common = {"gnss": "truth", "truth_pos_sigma_m": [1.0, 1.0, 5.0], "truth_vel_sigma_m_per_s": 0.005,
              "align": "truth", "init_heading_error_deg": heading_error_deg,
              "p0_att_deg": [1.0, 1.0, 1.5 * heading_error_deg], "attitude_sigma_deg": 0.3,
              "attitude_source": "truth"}  # Badshah's 0.3 deg attitude: the truth plus that noise
    out, curves = {}, {}
    with open_dataset(path) as ds:
        for use in (True, False):
            sol = SOLVERS["kf21"](ds, {**common, "use_attitude": use}, False)
            t, dp, dv, de = errors_vs_truth(ds, sol)
            key = "with_attitude" if use else "without_attitude"
            h = np.degrees(np.abs(de[:, 2]))
            curves[key] = (t, np.degrees(de[:, 2]))
            after = t >= 100.0
            out[key] = {f"heading_err_deg_at_{s}s": float(h[np.searchsorted(t, s)]) for s in (10, 20, 30, 60)}
            out[key]["first_time_below_0.5deg_s"] = float(t[np.argmax(h < 0.5)]) if (h < 0.5).any() else None
            out[key]["vel_rms_after_100s_m_per_s"] = np.sqrt(np.mean(dv[after] ** 2, axis=0)).round(4).tolist()
            out[key]["pos_rms_after_100s_m"] = np.sqrt(np.mean(dp[after] ** 2, axis=0)).round(3).tolist()
    if plot:
        _plot_heading(curves, plot)
    return out


def spp_bias(path, antenna=0) -> dict:
    """SPP position error of antenna ``antenna`` vs its true phase centre (ENU mean and RMS, m), without
    (``ionosphere = none``) and with (``broadcast``) the file's Klobuchar correction."""
    from simkit.estimators.registry import DEFAULTS, spp_fixes

    out = {}
    with open_dataset(path) as ds:
        pos = ds["gnss/truth/antenna_pos_ecef"][:, antenna]
        for iono in ("none", "broadcast"):
            fx = spp_fixes(ds, {**DEFAULTS["spp"], "antenna": antenna, "ionosphere": iono})
            ok = np.isfinite(fx.pos_ecef).all(1)
            lla = ecef_to_lla(pos[ok])
            dp = ecef_to_enu_vec(fx.pos_ecef[ok] - pos[ok], lla[:, 0], lla[:, 1])
            out[iono] = {"correction": fx.ionosphere, "fixes": int(ok.sum()),
                         "mean_enu_m": dp.mean(0).round(3).tolist(),
                         "rms_enu_m": np.sqrt(np.mean(dp**2, axis=0)).round(3).tolist()}
    return out


def _plot_heading(curves, out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    for key, (t, e) in curves.items():
        ax.plot(t, e, label=key.replace("_", " "))
    ax.axhline(0.5, color="k", lw=0.5, ls=":")
    ax.axhline(-0.5, color="k", lw=0.5, ls=":")
    ax.set_xlim(0, 200)
    ax.set_ylim(-3, 12)
    ax.set_xlabel("time since start (s)")
    ax.set_ylabel("heading error (deg)")
    ax.set_title("kf21 on airborne_stim300, 10 deg initial heading error")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def wu(runs=10, seed0=1, workdir=None, skip_s=10.0, coloured=True) -> dict:
    """Monte Carlo of KF vs H-infinity on high_dynamic with coloured IMU noise the filters do not model (or,
    with ``coloured`` False, with the preset's white noise and turn-on biases, which they model exactly)."""
    from simkit.pipeline import run as simulate

    cols = ["pos_E_m", "pos_N_m", "pos_U_m", "vel_E_m_per_s", "vel_N_m_per_s", "vel_U_m_per_s", "pitch_deg",
            "roll_deg", "heading_deg"]
    table = {"kf15": [], "hinf": []}
    with tempfile.TemporaryDirectory(dir=workdir) as d:
        for i in range(runs):
            path = simulate("high_dynamic", out=Path(d) / f"hd{i}.h5", seed=seed0 + i,
                              overrides=WU_COLOURED if coloured else [])
            with open_dataset(path) as ds:
                for name in table:
                    sol = SOLVERS[name](ds, {**WU_GNSS, "seed": seed0 + i}, False)
                    table[name].append(rms_table(ds, sol, skip_s))
    res = {name: dict(zip(cols, np.sqrt(np.mean(np.square(v), axis=0)).round(5).tolist()))
           for name, v in table.items()}
    res["hinf_over_kf"] = {c: round(res["hinf"][c] / res["kf15"][c], 3) for c in cols}
    res["runs"], res["coloured_noise"] = runs, coloured
    return res


def pyins_seeds(seeds, scenario="airborne_stim300", workdir=None, boot=5000) -> dict:
    """kf15 against pyins over several seeds of ``scenario`` (:func:`studies.pyins_peer.compare_pyins` per
    seed): the RMS over the runs of each filter's per-run RMS, their ratio with a 95 % bootstrap interval over the
    seeds, and on how many seeds simkit is at least as accurate, per axis."""
    from simkit.pipeline import run as simulate
    from studies.pyins_peer import compare_pyins

    ours, theirs = [], []
    with tempfile.TemporaryDirectory(dir=workdir) as d:
        for seed in seeds:
            res = compare_pyins(simulate(scenario, out=Path(d) / f"run{seed}.h5", seed=seed))
            ours.append(list(res["simkit_kf15"].values()))
            theirs.append(list(res["pyins"].values()))
    cols = list(res["pyins"])
    o, t = np.array(ours), np.array(theirs)
    ratio = np.sqrt(np.mean(o ** 2, 0) / np.mean(t ** 2, 0))
    pick = np.random.default_rng(0).integers(0, len(o), (boot, len(o)))
    lo, hi = np.percentile(np.sqrt(np.mean(o[pick] ** 2, 1) / np.mean(t[pick] ** 2, 1)), [2.5, 97.5], axis=0)
    return {"scenario": scenario, "seeds": list(seeds),
            "simkit_kf15": dict(zip(cols, np.sqrt(np.mean(o ** 2, 0)).round(5).tolist())),
            "pyins": dict(zip(cols, np.sqrt(np.mean(t ** 2, 0)).round(5).tolist())),
            "ratio": dict(zip(cols, ratio.round(3).tolist())),
            "ratio_95": dict(zip(cols, np.column_stack([lo, hi]).round(3).tolist())),
            "simkit_not_worse_runs": dict(zip(cols, (o <= t).sum(0).tolist()))}


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m studies.estimators", description=__doc__.splitlines()[0])
    p.add_argument("study", choices=("drift", "badshah", "wu", "pyins", "spp"))
    p.add_argument("file", nargs="?")
    p.add_argument("--seconds", type=float)
    p.add_argument("--plot")
    p.add_argument("--runs", type=int, default=10)
    p.add_argument("--white", action="store_true")
    p.add_argument("--seeds", help="pyins without FILE: comma-separated seeds of airborne_stim300")
    a = p.parse_args(argv)
    if a.study == "drift":
        res = drift(a.file, a.seconds)
    elif a.study == "badshah":
        res = badshah(a.file, a.plot)
    elif a.study == "wu":
        res = wu(a.runs, coloured=not a.white)
    elif a.study == "spp":
        res = spp_bias(a.file)
    elif a.file is None and a.seeds:
        res = pyins_seeds([int(x) for x in a.seeds.split(",")])
    else:
        from studies.pyins_peer import compare_pyins
        res = compare_pyins(a.file)
    print(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
