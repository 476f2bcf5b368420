"""The receiver's C/N0 as it reports it: an estimate with its own noise, written at the receiver's resolution.

A receiver does not output the C/N0 of the signal: it outputs an estimate (narrowband-wideband power ratio or
moments estimators averaged over a second or less), whose scatter about the true value grows as the averaging
shortens, then writes it at its output resolution: whole dB-Hz for many mass-market receivers (the Berlin drive in
docs/real_data.md), 0.25 dB-Hz or finer for geodetic ones. ``[gnss.cn0_report]`` models both:

    reported = round((C/N0 + sigma_db * z) / resolution_dbhz) * resolution_dbhz

with z a standard normal drawn per epoch, antenna, satellite and signal (the streams ``gnss/cn0_report/ant<a>/<sat
id>``, keyed by epoch like the observables' noise, so the other terms' draws are unchanged), rounding to the nearest
step (``resolution_dbhz = 0``: no rounding). The thermal noise of code, carrier and Doppler follows the true C/N0,
stored in ``/gnss/truth/<signal>/cn0`` when the table is given. Without the table the reported value is the true one
(files as before).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..section import Section, in_range, non_negative


@dataclass(frozen=True)
class Cn0ReportConfig:
    sigma_db: float = 0.0          # 1-sigma of the receiver's C/N0 estimate about the true C/N0, per epoch (dB)
    resolution_dbhz: float = 0.0   # output step of the reported C/N0 (dB-Hz); 0: not rounded


def parse_cn0_report(sec: Section) -> Cn0ReportConfig | None:
    """Read ``[gnss.cn0_report]`` (``sec`` at path "gnss.cn0_report"); None when the table is absent."""
    if not (sec.has("sigma_db") or sec.has("resolution_dbhz")):
        sec.done()   # an empty table, or one with only unknown keys: those are reported as unknown
        return None
    cfg = Cn0ReportConfig(sigma_db=sec.get("sigma_db", float, 0.0, check=in_range(0.0, 20.0)),
                          resolution_dbhz=sec.get("resolution_dbhz", float, 0.0, check=non_negative))
    sec.done()
    return cfg


def reported(cn0: np.ndarray, z: np.ndarray, cfg: Cn0ReportConfig) -> np.ndarray:
    """The reported C/N0 (dB-Hz) of the true ``cn0`` (dB-Hz) with the unit normals ``z`` (same shape)."""
    out = cn0 + cfg.sigma_db * z if cfg.sigma_db > 0 else cn0
    return np.round(out / cfg.resolution_dbhz) * cfg.resolution_dbhz if cfg.resolution_dbhz > 0 else out
