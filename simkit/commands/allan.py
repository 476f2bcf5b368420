"""``simkit allan FILE.h5``: overlapping Allan deviation of the recorded IMU output, fitted IEEE 952 terms, plot.

Every check on the arguments and the file runs before any computing; bad input is one line on stderr and exit 2.
"""
from __future__ import annotations

import json
import sys

import numpy as np

from ..atomic import atomic_open
from ..errors import DataFileError, ScenarioError
from ..io.output import check_output
from . import silence_stdout

UNITS = {"gyro": {"Q": "rad", "N": "rad/s^0.5", "B": "rad/s", "K": "rad/s^1.5", "R": "rad/s^2", "sigma": "rad/s"},
         "accel": {"Q": "m/s", "N": "m/s^1.5", "B": "m/s^2", "K": "m/s^2.5", "R": "m/s^3", "sigma": "m/s^2"}}
TRUTH = {"gyro": "truth/omega_ib_b", "accel": "truth/f_ib_b"}
MAX_GAUSS_MARKOV = 3   # the correlation-time grid search fits C(25, N) models: 2300 at N = 3


def add_parser(sub):
    p = sub.add_parser("allan", help="Allan deviation and noise-term fit of the IMU data in a file",
                       description="Compute the overlapping Allan deviation of /imu/gyro or /imu/accel per axis "
                                   "and fit the IEEE Std 952 terms Q, N, B, K, R (+ Gauss-Markov terms).")
    p.add_argument("file", help="simkit HDF5 file (reads /imu/t and /imu/gyro or /imu/accel)")
    p.add_argument("--sensor", choices=("gyro", "accel"), default="gyro")
    p.add_argument("--gauss-markov", type=int, default=0, metavar="N",
                   help=f"number of Gauss-Markov terms to fit (0 to {MAX_GAUSS_MARKOV})")
    p.add_argument("--raw", action="store_true",
                   help="analyse the raw measurement; by default the truth (/truth/omega_ib_b or /truth/f_ib_b) is "
                        "subtracted so that vehicle motion does not mask the sensor noise")
    p.add_argument("--plot", metavar="OUT.png", help="save the ADEV plot (needs matplotlib: the 'plot' extra)")
    p.add_argument("--json", metavar="OUT", help="write the fitted terms as JSON")
    return p


def _check_gauss_markov(n_gm: int):
    if n_gm < 0:
        raise ScenarioError("--gauss-markov", f"must be >= 0, got {n_gm}")
    if n_gm > MAX_GAUSS_MARKOV:
        raise ScenarioError("--gauss-markov", f"at most {MAX_GAUSS_MARKOV} Gauss-Markov terms, got {n_gm}")


def _check_record(n_samples: int, n_gm: int, path):
    """Enough Allan points for the fit: at least as many as fitted coefficients."""
    from ..imu.allan import TERMS, default_multiples

    points = len(default_multiples(n_samples)) if n_samples >= 3 else 0
    need = len(TERMS) + n_gm
    if points < need:
        what = f"{len(TERMS)} IEEE terms" + (f" + {n_gm} Gauss-Markov" if n_gm else "")
        raise DataFileError(path, f"record too short: {n_samples} IMU samples give {points} Allan points, fitting "
                                  f"{what} needs at least {need}" + (" (fewer --gauss-markov terms?)" if n_gm else ""))


def _read(args):
    """(dt, y, what, preset): the sample interval, the (N, 3) series to analyse, what it is, the IMU preset."""
    from .. import open as open_file

    sensor = args.sensor
    with open_file(args.file) as ds:
        if "imu/t" not in ds or f"imu/{sensor}" not in ds:
            raise DataFileError(args.file, f"no /imu/t and /imu/{sensor} datasets (the scenario has no [imu]?)")
        t_arr, y_arr = ds["imu/t"], ds[f"imu/{sensor}"]
        if y_arr.shape != (len(t_arr), 3):
            raise DataFileError(args.file, f"/imu/{sensor} must be (N, 3) with N = len(/imu/t) = {len(t_arr)}, "
                                           f"got {y_arr.shape}")
        _check_record(len(t_arr), args.gauss_markov, args.file)
        t01 = t_arr[:2]
        if not t01[1] > t01[0]:
            raise DataFileError(args.file, f"/imu/t does not increase ({t01[0]!r}, {t01[1]!r}): no sample rate")
        rate = ds.rate_hz("imu")
        y, what = y_arr[:], f"/imu/{sensor}"
        truth = TRUTH[sensor]
        if not args.raw and truth in ds and ds[truth].shape == y.shape:
            y, what = y - ds[truth][:], f"{what} - /{truth}"
        preset = ds.group_attrs("imu", decode_json=True).get("preset", "")
    return 1.0 / rate, y, what, preset


def run(args) -> int:
    from ..imu.allan import adev, fit

    for option, out in (("--json", args.json), ("--plot", args.plot)):
        if out is not None:
            check_output(out, [args.file], option=option)
    _check_gauss_markov(args.gauss_markov)
    if args.plot:
        from ..plots import image_format

        image_format(args.plot)
    dt, y, what, preset = _read(args)
    taus, dev, counts = adev(y, dt)
    flat = [axis for a, axis in enumerate("xyz") if not np.all(np.isfinite(dev[:, a])) or not np.any(dev[:, a] > 0)]
    if flat:
        raise DataFileError(args.file, f"/imu/{args.sensor} axis {', '.join(flat)}: no noise to analyse (zero or "
                                       f"non-finite Allan deviation; an ideal IMU? --raw analyses the measurement)")
    results = {axis: fit(taus, dev[:, a], counts, n_gm=args.gauss_markov) for a, axis in enumerate("xyz")}
    _print_table(args.sensor, f"{args.file}: {what}", dt, y.shape[0], preset, results)
    if args.plot:
        from ..plots import allan_figure

        allan_figure(args.plot, taus, dev, results, args.sensor, UNITS[args.sensor]["sigma"])
    if args.json:
        payload = {"file": args.file, "sensor": args.sensor, "rate_hz": 1 / dt, "units": UNITS[args.sensor],
                   "tau_s": taus.tolist(), "adev": dev.T.tolist(),
                   "fit": {axis: res.as_dict() for axis, res in results.items()}}
        with atomic_open(args.json, "w") as f:  # never half a file
            f.write(json.dumps(payload, indent=2))
    return 0


def _print_table(sensor, what, dt, n, preset, results):
    """The fitted terms on stdout; a reader that closes the pipe early (``| head``) ends the output quietly."""
    units = UNITS[sensor]
    lines = [f"{what}{f' (preset {preset})' if preset else ''}, {n} samples at {1 / dt:g} Hz "
             f"(IEEE Std 952 terms, two-sided PSD; bias instability B = ADEV floor / 0.664)",
             f"{'axis':>4} " + " ".join(f"{k + ' [' + units[k] + ']':>18}" for k in "QNBKR") + "   Gauss-Markov"]
    for axis, res in results.items():
        gm = ", ".join(f"sigma {s:.3g} {units['sigma']} tau {t:.3g} s" for s, t in res.gauss_markov)
        lines.append(f"{axis:>4} " + " ".join(f"{getattr(res, k):18.4g}" for k in "QNBKR") + f"   {gm or '-'}")
    try:
        sys.stdout.write("\n".join(lines) + "\n")
        sys.stdout.flush()
    except BrokenPipeError:
        silence_stdout()  # the JSON and plot asked for are still written
