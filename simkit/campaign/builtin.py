"""Built-in error statistics of one run, from the true error terms the simulator stores.

``imu_errors``: RMS of every ``/imu/errors/<term>`` and of measured - true rate and specific force.
``gnss_errors``: RMS of the thermal noise, multipath, ionospheric and tropospheric terms of ``/gnss/truth`` over
tracked observations, and the mean number of satellites tracked.
"""
from __future__ import annotations

import numpy as np

from ..io import gnss_signals, has, members, read_gnss, read_imu, read_truth
from .registry import register

_GNSS_TERMS = ("noise_code", "noise_carrier", "multipath_code", "multipath_carrier", "ionosphere")


def rms(x: np.ndarray) -> float:
    """Root mean square of the finite entries of ``x`` (NaN when there are none)."""
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    return float(np.sqrt(np.mean(x * x))) if x.size else float("nan")


@register("imu_errors")
def imu_errors(ds) -> dict:
    """RMS over samples and axes of every true IMU error term ``/imu/errors/<term>`` (rad/s for gyro_*, m/s^2 for
    accel_*), and of the total measured - true body rate (``gyro_total_rms``, rad/s) and specific force
    (``accel_total_rms``, m/s^2), both in body axes."""
    if not has(ds, "imu", "gyro"):
        return {}
    imu = read_imu(ds, fields=("gyro", "accel"), errors=sorted(members(ds, "imu_errors")))
    truth = read_truth(ds, fields=("omega_ib_b", "f_ib_b"), required=("omega_ib_b", "f_ib_b"))
    out = {f"{term}_rms": rms(x) for term, x in imu.errors.items()}
    out["gyro_total_rms"] = rms(imu.gyro - truth.omega_ib_b)
    out["accel_total_rms"] = rms(imu.accel - truth.f_ib_b)
    return out


@register("gnss_errors")
def gnss_errors(ds) -> dict:
    """Per signal ``<sig>_<term>_rms`` (m) over tracked epochs, antennas and satellites for the terms of
    ``/gnss/truth/<sig>`` (noise_code, noise_carrier, multipath_code, multipath_carrier, ionosphere);
    ``troposphere_rms`` (m) over observations tracked on any signal; ``<sig>_sats_tracked_mean``, the mean number
    of satellites with a carrier on antenna 0 per epoch."""
    if not gnss_signals(ds):
        return {}
    out = {}
    tracked_any = None
    for sig in gnss_signals(ds):
        g = read_gnss(ds, signals=[sig], obs=("carrier",), truth=[f"{sig}/{t}" for t in _GNSS_TERMS],
                      satellites=False)
        tracked = np.isfinite(g.obs["carrier"][sig])
        tracked_any = tracked if tracked_any is None else tracked_any | tracked
        out[f"{sig}_sats_tracked_mean"] = float(tracked[:, 0, :].sum(axis=1).mean()) if tracked.size else None
        for term in _GNSS_TERMS:
            if f"{sig}/{term}" in g.truth:
                out[f"{sig}_{term}_rms"] = rms(np.where(tracked, g.truth[f"{sig}/{term}"], np.nan))
    tropo = read_gnss(ds, signals=(), truth=("troposphere",), satellites=False).truth.get("troposphere")
    if tracked_any is not None and tropo is not None:
        out["troposphere_rms"] = rms(np.where(tracked_any, tropo, np.nan))
    return out
