"""Attitude error with fixed ambiguities against its predictions ("ATDOP times the carrier noise",
docs/attitude.md).

``python -m studies.atdop FILE [--set key=value ...]`` prints JSON: per axis [pitch, roll,
heading] the RMS error of the ``attitude`` solver's fixed epochs (status 1, single epoch) against /truth/euler,
and its ratio to three predictions (RMS over the same epochs): the propagated covariance, Wang's unit-weight
ATDOP x sigma_DD, and the weighted ATDOP (the actual DD covariance) x sigma_DD. ``--set`` goes to the solver.
"""
from __future__ import annotations

import argparse
import json

import numpy as np

from simkit.attitude.solvers import solver
from simkit.frames import wrap


def ratios(ds, params: dict | None = None) -> dict:
    """The figures of the module docstring for a simkit file ``ds``."""
    sol = solver("attitude")(ds, {"continuity": 0, **(params or {})}, False)
    fixed = sol.extras["status"] == 1
    tt = ds["truth/t"][:]
    truth = ds["truth/euler"][:][np.clip(np.searchsorted(tt, sol.t[fixed] - 1e-9), 0, len(tt) - 1)]
    d = sol.euler[fixed] - truth
    d[:, 2] = wrap(d[:, 2])
    rms = np.sqrt(np.mean(d ** 2, axis=0))
    sig = sol.extras["sigma_dd_carrier"][fixed][:, None]
    pred = {"covariance": np.sqrt(np.mean(np.diagonal(sol.cov[fixed], axis1=1, axis2=2), axis=0)),
            "atdop": np.sqrt(np.mean((sol.extras["atdop"][fixed] * sig) ** 2, axis=0)),
            "atdop_weighted": np.sqrt(np.mean((sol.extras["atdop_weighted"][fixed] * sig) ** 2, axis=0))}
    deg = lambda x: [round(float(v), 4) for v in np.degrees(x)]  # noqa: E731
    out = {"epochs_fixed": int(fixed.sum()), "epochs": int(fixed.size), "rms_deg": deg(rms)}
    for name, p in pred.items():
        out[f"{name}_deg"] = deg(p)
        out[f"ratio_{name}"] = [round(float(v), 3) for v in rms / p]
    return out


def main(argv=None):
    from simkit.io import open_dataset
    p = argparse.ArgumentParser(prog="python -m studies.atdop", description=__doc__.splitlines()[0])
    p.add_argument("file")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="attitude solver parameter")
    a = p.parse_args(argv)
    from simkit.params import parse_set

    params = parse_set(a.set, prefix="")  # TOML literals, as simkit solve --set
    with open_dataset(a.file) as ds:
        print(json.dumps(ratios(ds, params), indent=1))


if __name__ == "__main__":
    main()
