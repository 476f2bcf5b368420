"""Scenario regression: recompute a scenario (shortened) and compare its statistics with stored golden values.

The statistics of a run are named quantities (``imu/gyro-truth.std[x]``, ``gnss/L1C/noise_code.std``,
``truth/pos_ecef[-1][0]`` ...) computed from the file the run writes: the truth's final state, the standard
deviation of every IMU error process and of the measured-minus-true IMU output per axis, per signal the standard
deviation of the code/carrier/Doppler noise and multipath, the mean C/N0 and the mean number of tracked
satellites. Same scenario + seed gives the same arrays bit for bit, so the default tolerance is tight
(relative 1e-6 plus an absolute 1e-9 in the quantity's SI unit): a changed noise parameter, trajectory or
constellation shows as the quantities it moved, each with its golden and new value.

Golden file (JSON): {scenario name: {"duration_s", "overrides", "rtol", "atol", "quantities": {name: value}}}.
"""
from __future__ import annotations

import json
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..io import gnss_signals, has, members, open_dataset, read_gnss, read_imu, read_truth
from .errors import RefereeInputError

GOLDEN = Path(__file__).resolve().parents[1] / "data" / "golden" / "regress.json"
SHORT_S = {"quickstart": 5.0, "high_dynamic": 3.0, "airborne_stim300": 5.0, "xian_static_bds": 5.0}
DEFAULT_SHORT_S = 5.0
RTOL, ATOL = 1e-6, 1e-9


@dataclass(frozen=True)
class Drift:
    """One quantity outside tolerance: ``golden`` and ``value`` (None when absent on that side)."""

    scenario: str
    quantity: str
    golden: float | None
    value: float | None

    def __str__(self) -> str:
        if self.golden is None or self.value is None:
            return f"{self.scenario}: {self.quantity}: golden {self.golden}, now {self.value}"
        rel = abs(self.value - self.golden) / abs(self.golden) if self.golden else float("inf")
        return (f"{self.scenario}: {self.quantity} drifted from {self.golden:.9g} to {self.value:.9g} "
                f"({self.value - self.golden:+.3g}, {100 * rel:.3g} %)")


def _axes(prefix: str, x: np.ndarray, fn=np.std) -> dict[str, float]:
    return {f"{prefix}[{a}]": float(v) for a, v in zip("xyz", fn(x, axis=0))}


NOISE_TERMS = ("noise_code", "noise_carrier", "noise_doppler", "multipath_code", "multipath_carrier")


def _gnss_statistics(ds) -> dict[str, float]:
    out = {}
    for sig in gnss_signals(ds):
        g = read_gnss(ds, signals=[sig], obs=("code", "cn0"), truth=[f"{sig}/{t}" for t in NOISE_TERMS],
                      satellites=False)
        tracked = np.isfinite(g.obs["code"][sig])
        out[f"gnss/{sig}/tracked.mean"] = float(tracked.sum(axis=-1).mean())
        out[f"gnss/{sig}/cn0.mean"] = float(np.nanmean(g.obs["cn0"][sig]))
        for term in NOISE_TERMS:
            if f"{sig}/{term}" in g.truth:
                out[f"gnss/{sig}/{term}.std"] = float(np.nanstd(g.truth[f"{sig}/{term}"][tracked]))
    return out


def statistics(path) -> dict[str, float]:
    """The named regression quantities of a simkit file (module docstring), SI units."""
    out = {}
    with open_dataset(path) as ds:
        truth = read_truth(ds, fields=("pos_ecef", "vel_enu", "euler", "omega_ib_b", "f_ib_b"),
                           required=("pos_ecef", "vel_enu", "euler"))
        for key in ("pos_ecef", "vel_enu", "euler"):
            out.update({f"truth/{key}[-1][{i}]": float(v) for i, v in enumerate(getattr(truth, key)[-1])})
        if has(ds, "imu", "gyro"):
            imu = read_imu(ds, fields=("gyro", "accel"), errors=members(ds, "imu_errors"))
            out.update(_axes("imu/gyro-truth.std", imu.gyro - truth.omega_ib_b))
            out.update(_axes("imu/accel-truth.std", imu.accel - truth.f_ib_b))
            for term, x in imu.errors.items():
                out.update(_axes(f"imu/errors/{term}.std", x))
        if gnss_signals(ds):
            out.update(_gnss_statistics(ds))
    return out


def recompute(scenario, duration_s: float, overrides=(), workdir=None) -> dict[str, float]:
    """Run ``scenario`` (path, bundled name or dict) for ``duration_s`` seconds and return its statistics."""
    from ..pipeline import run as simulate

    with tempfile.TemporaryDirectory(dir=workdir) as tmp:
        out = simulate(scenario, out=Path(tmp) / "regress.h5",
                       overrides=[*overrides, f"scenario.duration_s={duration_s!r}"])
        return statistics(out)


def compare(name: str, golden: dict, values: dict, rtol: float = RTOL, atol: float = ATOL) -> list[Drift]:
    """Every quantity whose value differs from its golden value by more than ``atol + rtol |golden|``, and every
    quantity present on one side only."""
    drifts = []
    for q in sorted(set(golden) | set(values)):
        g, v = golden.get(q), values.get(q)
        same_nan = g is not None and v is not None and np.isnan(g) and np.isnan(v)
        if g is None or v is None or not (same_nan or abs(v - g) <= atol + rtol * abs(g)):
            drifts.append(Drift(name, q, g, v))
    return drifts


def load_golden(path=GOLDEN) -> dict:
    """The golden table (module docstring) of ``path``."""
    path = Path(path)
    if not path.is_file():
        raise RefereeInputError(path, "no golden file (create one with simkit regress --update)")
    try:
        data = json.loads(path.read_text())
    except ValueError as exc:
        raise RefereeInputError(path, f"not valid JSON: {exc}") from None
    for name, entry in data.items():
        if not isinstance(entry, dict) or "quantities" not in entry or "duration_s" not in entry:
            raise RefereeInputError(path, f"{name}: expected duration_s and quantities")
    return data


def check(name: str, scenario, golden_entry: dict, overrides=(), workdir=None) -> list[Drift]:
    """Recompute ``scenario`` as its golden entry says (shortened, with the entry's overrides plus
    ``overrides``) and return the drifts."""
    values = recompute(scenario, golden_entry["duration_s"], [*golden_entry.get("overrides", []), *overrides],
                       workdir)
    return compare(name, golden_entry["quantities"], values, golden_entry.get("rtol", RTOL),
                   golden_entry.get("atol", ATOL))


def golden_entry(scenario, duration_s: float, overrides=(), workdir=None) -> dict:
    """A fresh golden entry for ``scenario``."""
    return {"duration_s": duration_s, "overrides": list(overrides), "rtol": RTOL, "atol": ATOL,
            "quantities": recompute(scenario, duration_s, overrides, workdir)}
