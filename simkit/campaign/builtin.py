"""Built-in error statistics of one run, from the true error terms the simulator stores.

``imu_errors``: RMS of every ``/imu/errors/<term>`` and of measured - true rate and specific force.
``gnss_errors``: RMS of the thermal noise, multipath, ionospheric and tropospheric terms of ``/gnss/truth`` over
tracked observations, and the mean number of satellites tracked.
"""
from __future__ import annotations

import numpy as np

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
    if "imu/gyro" not in ds:
        return {}
    out = {f"{term}_rms": rms(ds[f"imu/errors/{term}"][()]) for term in sorted(ds.members("imu/errors"))}
    out["gyro_total_rms"] = rms(ds["imu/gyro"][()] - ds["truth/omega_ib_b"][()])
    out["accel_total_rms"] = rms(ds["imu/accel"][()] - ds["truth/f_ib_b"][()])
    return out


@register("gnss_errors")
def gnss_errors(ds) -> dict:
    """Per signal ``<sig>_<term>_rms`` (m) over tracked epochs, antennas and satellites for the terms of
    ``/gnss/truth/<sig>`` (noise_code, noise_carrier, multipath_code, multipath_carrier, ionosphere);
    ``troposphere_rms`` (m) over observations tracked on any signal; ``<sig>_sats_tracked_mean``, the mean number
    of satellites with a carrier on antenna 0 per epoch."""
    if "gnss/signals" not in ds:
        return {}
    out = {}
    tracked_any = None
    for sig in ds["gnss/signals"][()]:
        tracked = np.isfinite(ds[f"gnss/obs/{sig}/carrier"][()])
        tracked_any = tracked if tracked_any is None else tracked_any | tracked
        out[f"{sig}_sats_tracked_mean"] = float(tracked[:, 0, :].sum(axis=1).mean()) if tracked.size else None
        for term in _GNSS_TERMS:
            path = f"gnss/truth/{sig}/{term}"
            if path in ds:
                out[f"{sig}_{term}_rms"] = rms(np.where(tracked, ds[path][()], np.nan))
    if tracked_any is not None and "gnss/truth/troposphere" in ds:
        out["troposphere_rms"] = rms(np.where(tracked_any, ds["gnss/truth/troposphere"][()], np.nan))
    return out
