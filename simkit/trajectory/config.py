"""The ``[trajectory]`` table: origin, initial state, options and segments -> a frozen :class:`TrajectoryConfig`.

Keys are documented in the README (units in their names); the segments are parsed and planned into command
profiles here, so a bad segment is reported when the scenario is loaded, naming its key.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..section import Section, in_range, positive
from .segments import KinematicState, plan


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


def _flight_path(v):
    return None if -90 < v < 90 else "must be in (-90, 90)"


def parse_config(sec: Section) -> TrajectoryConfig:
    """Read the ``[trajectory]`` table (a :class:`Section` at path "trajectory")."""
    rate = sec.get("rate_hz", float, check=in_range(1e-3, 1e5))
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
