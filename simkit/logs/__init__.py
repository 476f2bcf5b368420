"""Recorded logs as trajectories: readers for CSV, GPX, NMEA, KML/KMZ and simkit ``/solutions``, and the fit of
``[trajectory] source = FILE`` (docs/logs_and_export.md)."""
from __future__ import annotations

import hashlib
from dataclasses import replace
from datetime import datetime
from pathlib import Path

import numpy as np

from ..errors import DataFileError, ScenarioError
from ..trajectory import TrajectoryConfig
from ..trajectory.logged import LoggedPath
from . import nmea, table, xmltracks
from .record import Record

__all__ = ["Record", "read", "fit_trajectory", "log_path", "FORMAT_OF_SUFFIX"]

FORMAT_OF_SUFFIX = {".csv": "csv", ".gpx": "gpx", ".nmea": "nmea", ".nma": "nmea", ".log": "nmea",
                    ".kml": "kml", ".kmz": "kmz", ".h5": "h5", ".hdf5": "h5"}
_MARGIN_S = 30.0     # samples this far outside the run still steady the fit at its ends


def read(path, fmt: str | None = None, date_hint=None, solution: str | None = None) -> Record:
    """A log file as a :class:`Record`; ``fmt`` one of csv, gpx, nmea, kml, kmz, h5 (default: from the suffix)."""
    path = Path(path)
    fmt = fmt or FORMAT_OF_SUFFIX.get(path.suffix.lower())
    if fmt is None:
        raise DataFileError(path, f"unknown log format of suffix {path.suffix!r}: expected one of "
                                  f"{', '.join(sorted(FORMAT_OF_SUFFIX))}, or set trajectory.format")
    if not path.is_file():
        raise DataFileError(path, "no such file")
    if fmt == "csv":
        return table.read_csv(path)
    if fmt == "gpx":
        return xmltracks.read_gpx(path)
    if fmt == "nmea":
        return nmea.read(path, date_hint)
    if fmt in ("kml", "kmz"):
        return xmltracks.read_kml(path)
    return table.read_solution(path, solution)


def log_path(source: str, base: Path | None) -> Path:
    """The log file of ``[trajectory] source``: as given (the working folder), else relative to the scenario's
    folder ``base``."""
    path = Path(source).expanduser()
    if not path.is_absolute() and base is not None and not path.is_file():
        path = base / path
    return path


def fit_trajectory(cfg: TrajectoryConfig, base: Path | None, start: datetime, week: int, sow: float,
                   duration_s: float) -> TrajectoryConfig:
    """``cfg`` (with ``cfg.log``) with its log read, cut to the run (scenario start ``week``/``sow``, plus a
    margin) and fitted: ``path`` set, and the origin and initial state taken from the fitted path at t = 0."""
    spec = cfg.log
    path = log_path(spec.source, base)
    if not path.is_file():
        raise ScenarioError("trajectory.source", f"no such log file: {spec.source}")
    record = read(path, spec.format, start.date(), spec.solution)
    track = record.track(week, sow, -_MARGIN_S, duration_s + _MARGIN_S)
    if len(track.t) == 0 or track.t[0] > 1e-9 or track.t[-1] < duration_s - 1e-9:
        raise DataFileError(record.source, f"the log spans {record.span_text()}, which "
                                           f"does not cover scenario.start + {duration_s:g} s: move scenario.start "
                                           f"or shorten scenario.duration_s")
    track = _margins_without_gaps(track, spec.fit.max_gap_s, duration_s)
    fitted = LoggedPath(track, spec.fit, duration_s)
    fitted.provenance = {"source": spec.source, "sha256": hashlib.sha256(path.read_bytes()).hexdigest(),
                         "samples_used": int(len(track.t))}
    first = fitted.truth([0.0])
    lat, lon, h = first.pos_lla[0]
    pitch, roll, heading = first.euler[0]

    return replace(cfg, path=fitted, lat_rad=float(lat), lon_rad=float(lon), height_m=float(h),
                   speed_m_per_s=float(np.linalg.norm(first.vel_enu[0])), flight_path_rad=float(pitch),
                   heading_rad=float(heading), roll_rad=float(roll))


def _margins_without_gaps(track, max_gap_s: float, duration_s: float):
    """Drop the margin samples beyond a long gap that lies wholly outside the run: only a gap inside
    [0, duration_s] is the run's problem."""
    dt = np.diff(track.t)
    first, last = 0, len(track.t)
    for k in np.nonzero(dt > max_gap_s)[0]:
        if track.t[k + 1] <= 0.0:
            first = k + 1
        elif track.t[k] >= duration_s and last == len(track.t):
            last = k + 1
    return track.take(slice(first, last))
