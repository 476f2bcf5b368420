"""The ``[trajectory]`` table: origin, initial state, options and segments -> a frozen :class:`TrajectoryConfig`.

Keys are documented in the README (units in their names); the segments are parsed and planned into command
profiles here, so a bad segment is reported when the scenario is loaded, naming its key.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..section import Section, in_range, positive
from .logged import ATTITUDE_RULES, FitOptions
from .segments import KinematicState, plan

LOG_FORMATS = ("csv", "gpx", "nmea", "kml", "kmz", "h5")
_ANALYTIC_KEYS = ("origin", "initial", "segment", "coordinated_turns", "ramp_s")


@dataclass(frozen=True, kw_only=True)
class TrajectoryConfig:
    """The resolved trajectory: SI units and radians, initial state at t = 0 and the planned command profiles."""

    rate_hz: float                 # truth sample rate
    lat_rad: float                 # origin, geodetic
    lon_rad: float
    height_m: float                # ellipsoidal
    speed_m_per_s: float           # initial speed
    flight_path_rad: float         # initial flight-path angle (= pitch: body y follows the velocity)
    heading_rad: float             # initial heading, clockwise from north
    roll_rad: float                # initial roll on top of any coordinated bank
    coordinated_turns: bool        # bank = atan(V psi' cos(gamma) / g0) in turns
    segments: tuple                # planned profiles (Channel / WaypointPath) with .start, .end, .commands(t)
    planned_s: float               # end time of the last segment
    log: "LogSpec | None" = None   # a logged trajectory (``source``): what to read and how to fit it
    path: object = None            # its fitted :class:`~.logged.LoggedPath`, set when the scenario is loaded


@dataclass(frozen=True, kw_only=True)
class LogSpec:
    """``[trajectory] source = FILE`` and its options (docs/logs_and_export.md)."""

    source: str                    # as written; relative paths are relative to the scenario file
    format: str | None             # one of LOG_FORMATS; None: from the file name
    solution: str | None           # the /solutions group of a simkit file
    fit: FitOptions


def _flight_path(v):
    return None if -90 < v < 90 else "must be in (-90, 90)"


def parse_config(sec: Section) -> TrajectoryConfig:
    """Read the ``[trajectory]`` table (a :class:`Section` at path "trajectory")."""
    rate = sec.get("rate_hz", float, check=in_range(1e-3, 1e5))
    if sec.has("source"):
        return _parse_logged(sec, rate)
    origin = sec.section("origin", required=True)
    lat = np.radians(origin.get("lat_deg", float, check=in_range(-90, 90)))
    lon = np.radians(origin.get("lon_deg", float, check=in_range(-180, 360)))
    height = origin.get("height_m", float, 0.0, check=in_range(-1e3, 1e6))
    origin.done()
    init = sec.section("initial")
    speed = init.get("speed_m_per_s", float, 0.0, check=lambda v: None if v >= 0 else "must be >= 0")
    gamma = np.radians(init.get("pitch_deg", float, 0.0, check=_flight_path))
    heading = np.radians(init.get("heading_deg", float, 0.0))
    roll = np.radians(init.get("roll_deg", float, 0.0))
    init.done()
    coordinated = sec.get("coordinated_turns", bool, True)
    ramp = sec.get("ramp_s", float, 1.0, check=positive)
    segments, planned = plan(sec.sections("segment"), KinematicState(speed, gamma, heading), ramp)
    sec.done()
    return TrajectoryConfig(rate_hz=rate, lat_rad=float(lat), lon_rad=float(lon), height_m=height,
                            speed_m_per_s=speed, flight_path_rad=float(gamma), heading_rad=float(heading),
                            roll_rad=float(roll), coordinated_turns=coordinated, segments=segments,
                            planned_s=planned)


def _sigma_triple(v):
    ok = (isinstance(v, (int, float)) and not isinstance(v, bool) and v > 0) or (
        isinstance(v, list) and len(v) == 3 and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                    and x > 0 for x in v))
    return None if ok else "expected a number > 0 or [east, north, up] numbers > 0 (m)"


def _parse_logged(sec: Section, rate: float) -> TrajectoryConfig:
    source = sec.get("source", str)
    for key in _ANALYTIC_KEYS:
        if sec.has(key):
            raise sec.error(key, "cannot be given with trajectory.source: a logged trajectory takes its origin, "
                                 "initial state and path from the log")
    fmt = sec.get("format", str, None, choices=LOG_FORMATS)
    solution = sec.get("solution", str, None)
    sigma = sec.get("position_sigma_m", object, None, check=_sigma_triple) if sec.has("position_sigma_m") else None
    sigma_v = sec.get("velocity_sigma_m_per_s", float, None, check=positive)
    attitude = sec.get("attitude", str, None, choices=ATTITUDE_RULES)
    att_sigma = sec.get("attitude_sigma_deg", float, None, check=positive)
    gap = sec.get("max_gap_s", float, 10.0, check=positive)
    vmax = sec.get("max_speed_m_per_s", float, 500.0, check=positive)
    outliers = sec.get("outliers", str, "refuse", choices=("refuse", "drop"))
    sec.done()
    fit = FitOptions(position_sigma_m=None if sigma is None else tuple(np.broadcast_to(np.asarray(sigma, float), 3)),
                     velocity_sigma_m_per_s=sigma_v, attitude=attitude,
                     attitude_sigma_rad=None if att_sigma is None else float(np.radians(att_sigma)),
                     max_gap_s=gap, max_speed_m_per_s=vmax, outliers=outliers)
    nan = float("nan")
    return TrajectoryConfig(rate_hz=rate, lat_rad=nan, lon_rad=nan, height_m=nan, speed_m_per_s=nan,
                            flight_path_rad=nan, heading_rad=nan, roll_rad=0.0, coordinated_turns=False,
                            segments=(), planned_s=0.0,
                            log=LogSpec(source=source, format=fmt, solution=solution, fit=fit))
