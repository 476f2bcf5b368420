"""``simkit allan FILE.h5``: overlapping Allan deviation of the recorded IMU output, fitted IEEE 952 terms, plot."""
from __future__ import annotations

import json

import numpy as np

from ..errors import DataFileError

UNITS = {"gyro": {"Q": "rad", "N": "rad/s^0.5", "B": "rad/s", "K": "rad/s^1.5", "R": "rad/s^2", "sigma": "rad/s"},
         "accel": {"Q": "m/s", "N": "m/s^1.5", "B": "m/s^2", "K": "m/s^2.5", "R": "m/s^3", "sigma": "m/s^2"}}


def add_parser(sub):
    p = sub.add_parser("allan", help="Allan deviation and noise-term fit of the IMU data in a file",
                       description="Compute the overlapping Allan deviation of /imu/gyro or /imu/accel per axis "
                                   "and fit the IEEE Std 952 terms Q, N, B, K, R (+ Gauss-Markov terms).")
    p.add_argument("file", help="simkit HDF5 file (reads /imu/t and /imu/gyro or /imu/accel)")
    p.add_argument("--sensor", choices=("gyro", "accel"), default="gyro")
    p.add_argument("--gauss-markov", type=int, default=0, metavar="N", help="number of Gauss-Markov terms to fit")
    p.add_argument("--raw", action="store_true",
                   help="analyse the raw measurement; by default the truth (/truth/omega_ib_b or /truth/f_ib_b) is "
                        "subtracted so that vehicle motion does not mask the sensor noise")
    p.add_argument("--plot", metavar="OUT.png", help="save the ADEV plot (needs matplotlib)")
    p.add_argument("--json", metavar="OUT", help="write the fitted terms as JSON")
    return p


TRUTH = {"gyro": "truth/omega_ib_b", "accel": "truth/f_ib_b"}


def _read(path: str, sensor: str, raw: bool = False):
    import h5py

    try:
        with h5py.File(path, "r") as h5:
            if f"imu/{sensor}" not in h5 or "imu/t" not in h5:
                raise DataFileError(path, f"no /imu/t and /imu/{sensor} datasets (not a simkit file with IMU data?)")
            t = h5["imu/t"][:]
            y = h5[f"imu/{sensor}"][:]
            if not raw and TRUTH[sensor] in h5 and h5[TRUTH[sensor]].shape == y.shape:
                y = y - h5[TRUTH[sensor]][:]
    except OSError as exc:
        raise DataFileError(path, f"cannot read as HDF5 ({exc})") from None
    if t.size < 3 or y.shape != (t.size, 3):
        raise DataFileError(path, f"/imu/{sensor} must be (N, 3) with N = len(/imu/t) >= 3, got {y.shape}")
    dt = float(np.median(np.diff(t)))
    return dt, y


def run(args) -> int:
    from ..imu.allan import adev, fit

    dt, y = _read(args.file, args.sensor, args.raw)
    taus, dev, counts = adev(y, dt)
    units = UNITS[args.sensor]
    results = {}
    what = f"/imu/{args.sensor}" + ("" if args.raw else f" - /{TRUTH[args.sensor]}")
    print(f"{args.file}: {what}, {y.shape[0]} samples at {1 / dt:g} Hz "
          f"(IEEE Std 952 terms, two-sided PSD; bias instability B = ADEV floor / 0.664)")
    print(f"{'axis':>4} " + " ".join(f"{k + ' [' + units[k] + ']':>18}" for k in "QNBKR") + "   Gauss-Markov")
    for a, axis in enumerate("xyz"):
        res = fit(taus, dev[:, a], counts, n_gm=args.gauss_markov)
        results[axis] = res.as_dict()
        gm = ", ".join(f"sigma {s:.3g} {units['sigma']} tau {t:.3g} s" for s, t in res.gauss_markov)
        print(f"{axis:>4} " + " ".join(f"{getattr(res, k):18.4g}" for k in "QNBKR") + f"   {gm or '-'}")
    if args.json:
        payload = {"file": args.file, "sensor": args.sensor, "rate_hz": 1 / dt, "units": units,
                   "tau_s": taus.tolist(), "adev": dev.T.tolist(), "fit": results}
        with open(args.json, "w") as fh:
            json.dump(payload, fh, indent=2)
    if args.plot:
        _plot(args.plot, taus, dev, results, args.sensor, units)
    return 0


def _plot(out, taus, dev, results, sensor, units):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise SystemExit("simkit allan --plot needs matplotlib: pip install 'simkit[plot]'") from None
    from ..imu.allan import AllanFit

    fig, ax = plt.subplots(figsize=(7, 5))
    for a, axis in enumerate("xyz"):
        line, = ax.loglog(taus, dev[:, a], ".", label=f"{axis} measured")
        d = dict(results[axis])
        gm = [(g["sigma"], g["tau_s"]) for g in d.pop("gauss_markov")]
        d.pop("rms_log_error")
        ax.loglog(taus, AllanFit(**d, gauss_markov=gm).adev(taus), "-", color=line.get_color(), label=f"{axis} fit")
    ax.set_xlabel("averaging time tau [s]")
    ax.set_ylabel(f"Allan deviation [{units['sigma']}]")
    ax.set_title(f"{sensor}: overlapping Allan deviation")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.savefig(out, dpi=120, bbox_inches="tight")
    plt.close(fig)
