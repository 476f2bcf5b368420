"""Motion segments: parsing ``[[trajectory.segment]]`` tables and planning them into command profiles.

Kinematic channels (all in the local-level ENU frame at the vehicle):
``accel`` = dV/dt (m/s^2, along the velocity), ``pitch_rate`` = d(gamma)/dt (flight-path angle rate, rad/s),
``turn_rate`` = d(psi)/dt (heading rate, clockwise positive, rad/s) with ``turn_accel`` its derivative, and
``roll_rate`` (rad/s, roll about body y added to any coordinated bank). Positive turn angles turn right.

Each segment kind is one entry of :data:`SEGMENT_KINDS`: a ``parse`` function that only reads and checks the
kind's keys (SI values out) and a ``plan`` function that only does kinematics: from the start time, the
:class:`KinematicState` at the start and the ramp time to the segment's profiles, duration and end state.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from ..earth import G0
from ..section import Section, positive
from .profiles import Plateau, Sinusoid
from .spline import WaypointPath, unit_velocity

RAD = np.pi / 180.0


@dataclass(frozen=True)
class Channel:
    """One smooth profile feeding one kinematic channel."""

    name: str
    profile: Plateau | Sinusoid

    @property
    def start(self):
        return self.profile.start

    @property
    def end(self):
        return self.profile.end

    def commands(self, t):
        value, deriv = self.profile.evaluate(t)
        out = {self.name: value}
        if self.name == "turn_rate":
            out["turn_accel"] = deriv
        return out


@dataclass(frozen=True)
class KinematicState:
    """What the planner tracks across segments: speed (m/s), flight-path angle and heading (rad)."""

    speed: float
    gamma: float
    heading: float


@dataclass(frozen=True)
class Planned:
    """A planned segment: its profiles (:class:`Channel` or :class:`WaypointPath`), duration (s), end state."""

    items: tuple
    duration: float
    state: KinematicState


class PlanError(Exception):
    """A segment whose keys are valid but cannot be flown from the state it starts in; names the key."""

    def __init__(self, key: str, message: str):
        super().__init__(message)
        self.key, self.message = key, message


@dataclass(frozen=True)
class SegmentKind:
    parse: Callable[[Section], dict]      # the kind's keys -> keyword arguments of ``plan`` (SI)
    plan: Callable[..., Planned]          # plan(t0, state, ramp, **spec)


def plan(sections: list[Section], state: KinematicState, default_ramp: float) -> tuple[tuple, float]:
    """Turn segment tables into (profiles with .start/.end/.commands, planned end time)."""
    items, t = [], 0.0
    for sec in sections:
        kind = SEGMENT_KINDS[sec.get("kind", str, choices=KINDS)]
        ramp = sec.get("ramp_s", float, default_ramp, check=positive)
        spec = kind.parse(sec)
        sec.done()
        try:
            planned = kind.plan(t, state, ramp, **spec)
        except PlanError as exc:
            raise sec.error(exc.key, exc.message) from None
        items.extend(planned.items)
        t += planned.duration
        state = planned.state
    return tuple(items), t


# ---- key parsing (no kinematics) ----

def _nonzero(v):
    return None if v != 0 else "must be non-zero"


def _above_one(v):
    return None if v > 1 else "must be > 1"


def _flight_path(v):
    return None if -90 < v < 90 else "must be in (-90, 90)"


def _one_of(sec: Section, keys: tuple[str, ...]) -> str:
    given = [k for k in keys if sec.has(k)]
    if len(given) != 1:
        raise sec.error(keys[0], "give exactly one of " + ", ".join(keys))
    return given[0]


def _direction(sec: Section, choices=("right", "left")) -> float:
    return 1.0 if sec.get("direction", str, choices[0], choices=choices) == choices[0] else -1.0


def _parse_duration(sec: Section) -> dict:
    return {"duration": sec.get("duration_s", float, check=positive)}


def _parse_accelerate(sec: Section) -> dict:
    spec = {"accel": sec.get("accel_m_per_s2", float, check=positive)}
    if sec.has("target_speed_m_per_s"):
        spec["target"] = sec.get("target_speed_m_per_s", float, check=lambda v: None if v >= 0 else "must be >= 0")
    else:
        spec["duration"] = sec.get("duration_s", float, check=positive)
        spec["sign"] = _direction(sec, ("faster", "slower"))
    return spec


_TURN_KEYS = {"rate_deg_per_s": ("rate", RAD, _nonzero), "radius_m": ("radius", 1.0, positive),
              "load_factor_g": ("load_factor", 1.0, _above_one)}


def _parse_turn(sec: Section) -> dict:
    key = _one_of(sec, tuple(_TURN_KEYS))
    name, scale, check = _TURN_KEYS[key]
    spec = {name: sec.get(key, float, check=check) * scale}
    if sec.has("angle_deg"):
        spec["angle"] = sec.get("angle_deg", float, check=_nonzero) * RAD
        if name == "rate" and np.sign(spec["rate"]) != np.sign(spec["angle"]):
            raise sec.error("angle_deg", "has the opposite sign of rate_deg_per_s")
    else:
        spec["duration"] = sec.get("duration_s", float, check=positive)
        if name != "rate":
            spec["sign"] = _direction(sec)
    return spec


def _parse_climb(sec: Section) -> dict:
    return {"target": sec.get("flight_path_deg", float, check=_flight_path) * RAD,
            "rate": sec.get("pitch_rate_deg_per_s", float, 3.0, check=positive) * RAD}


def _parse_pullup(sec: Section) -> dict:
    return {"target": sec.get("flight_path_deg", float, check=_flight_path) * RAD,
            "load_factor": sec.get("load_factor_g", float, check=_above_one)}


def _parse_roll(sec: Section) -> dict:
    return {"rate": sec.get("rate_deg_per_s", float, check=_nonzero) * RAD,
            "rolls": sec.get("rolls", float, 1.0, check=positive)}


def _parse_loop(sec: Section) -> dict:
    if _one_of(sec, ("radius_m", "load_factor_g")) == "radius_m":
        spec = {"radius": sec.get("radius_m", float, check=positive)}
    else:
        spec = {"load_factor": sec.get("load_factor_g", float, check=_above_one)}
    return dict(spec, loops=sec.get("loops", float, 1.0, check=positive))


def _parse_weave(sec: Section) -> dict:
    period = sec.get("period_s", float, check=positive)
    cycles = sec.get("cycles", float, 1.0, check=positive)
    if _one_of(sec, ("heading_amplitude_deg", "rate_amplitude_deg_per_s")) == "heading_amplitude_deg":
        amplitude = sec.get("heading_amplitude_deg", float, check=positive) * RAD * 2.0 * np.pi / period
    else:
        amplitude = sec.get("rate_amplitude_deg_per_s", float, check=positive) * RAD
    return {"period": period, "cycles": cycles, "rate_amplitude": amplitude}


_RATE_KEYS = {"accel_m_per_s2": ("accel", 1.0), "pitch_rate_deg_per_s": ("pitch_rate", RAD),
              "turn_rate_deg_per_s": ("turn_rate", RAD), "roll_rate_deg_per_s": ("roll_rate", RAD)}


def _parse_rates(sec: Section) -> dict:
    values = {channel: sec.get(key, float, 0.0) * scale for key, (channel, scale) in _RATE_KEYS.items()}
    return {"duration": sec.get("duration_s", float, check=positive), "values": values}


def _is_triple(p) -> bool:
    return isinstance(p, list) and len(p) == 3 and all(
        isinstance(x, (int, float)) and not isinstance(x, bool) for x in p)


def _parse_waypoints(sec: Section) -> dict:
    points = sec.get("points_enu_m", list)
    if len(points) < 1 or not all(_is_triple(p) for p in points):
        raise sec.error("points_enu_m", f"expected an array of [east, north, up] triples in m, got {points!r}")
    pts = np.asarray(points, dtype=float)
    if np.any(np.linalg.norm(np.diff(np.vstack([np.zeros(3), pts]), axis=0), axis=1) == 0):
        raise sec.error("points_enu_m", "two consecutive waypoints coincide (the first point is the segment start)")
    return {"points": pts, "speed_end": sec.get("speed_m_per_s", float, None, check=positive)}


# ---- kinematics (no key parsing) ----

def _moving(s: KinematicState, kind: str):
    if s.speed <= 0.0:
        raise PlanError("kind", f"'{kind}' needs a moving vehicle, but the speed here is 0 m/s: accelerate first")


def _plan_static(t0, s, ramp, duration):
    if s.speed != 0.0:
        raise PlanError("kind", f"'static' needs speed 0, but the vehicle moves at {s.speed:g} m/s here")
    return Planned((), duration, s)


def _plan_cruise(t0, s, ramp, duration):
    return Planned((), duration, s)


def _speed_after(s: KinematicState, change: float, key: str) -> KinematicState:
    speed = s.speed + change
    if speed < -1e-9:
        raise PlanError(key, f"decelerates below zero speed ({speed:.3g} m/s at the end)")
    return replace(s, speed=max(speed, 0.0))


def _plan_accelerate(t0, s, ramp, accel, target=None, duration=None, sign=1.0):
    if target is not None:
        p = Plateau.for_change(t0, target - s.speed, accel, ramp)
    else:
        p = Plateau(t0, duration, min(ramp, duration / 2), sign * accel)
    return Planned((Channel("accel", p),), p.duration, _speed_after(s, p.integral(), "duration_s"))


def _plan_turn(t0, s, ramp, rate=None, radius=None, load_factor=None, angle=None, duration=None, sign=1.0):
    _moving(s, "turn")
    horizontal = s.speed * np.cos(s.gamma)
    if radius is not None:
        rate = sign * horizontal / radius
    elif load_factor is not None:
        rate = sign * G0 * np.sqrt(load_factor**2 - 1.0) / horizontal
    if angle is not None:
        p = Plateau.for_change(t0, angle, rate, ramp)   # turns towards the sign of the angle
    else:
        p = Plateau(t0, duration, min(ramp, duration / 2), rate)
    return Planned((Channel("turn_rate", p),), p.duration, replace(s, heading=s.heading + p.integral()))


def _plan_pitch_to(t0, s, ramp, target, rate=None, load_factor=None, kind="climb"):
    _moving(s, kind)
    if load_factor is not None:
        rate = G0 * (load_factor - 1.0) / s.speed
    p = Plateau.for_change(t0, target - s.gamma, rate, ramp)
    return Planned((Channel("pitch_rate", p),) if p.duration > 0 else (), p.duration, replace(s, gamma=target))


def _plan_pullup(t0, s, ramp, target, load_factor):
    return _plan_pitch_to(t0, s, ramp, target, load_factor=load_factor, kind="pullup")


def _plan_roll(t0, s, ramp, rate, rolls):
    p = Plateau.for_change(t0, np.sign(rate) * 2.0 * np.pi * rolls, rate, ramp)
    return Planned((Channel("roll_rate", p),), p.duration, s)


def _plan_loop(t0, s, ramp, loops, radius=None, load_factor=None):
    _moving(s, "loop")
    rate = s.speed / radius if radius is not None else G0 * (load_factor - 1.0) / s.speed
    p = Plateau.for_change(t0, 2.0 * np.pi * loops, rate, ramp)
    gamma = float(np.angle(np.exp(1j * (s.gamma + p.integral()))))
    return Planned((Channel("pitch_rate", p),), p.duration, replace(s, gamma=gamma))


def _plan_weave(t0, s, ramp, period, cycles, rate_amplitude):
    _moving(s, "weave")
    duration = period * cycles
    w = Sinusoid(t0, duration, min(ramp, duration / 2), rate_amplitude, period)
    return Planned((Channel("turn_rate", w),), duration, replace(s, heading=s.heading + w.integral()))


def _plan_rates(t0, s, ramp, duration, values):
    r = min(ramp, duration / 2)
    channels = tuple(Channel(name, Plateau(t0, duration, r, v)) for name, v in values.items() if v)
    area = {c.name: c.profile.integral() for c in channels}
    state = replace(s, gamma=s.gamma + area.get("pitch_rate", 0.0), heading=s.heading + area.get("turn_rate", 0.0))
    return Planned(channels, duration, _speed_after(state, area.get("accel", 0.0), "accel_m_per_s2"))


def _plan_waypoints(t0, s, ramp, points, speed_end=None):
    _moving(s, "waypoints")
    v_start = s.speed * unit_velocity(s.gamma, s.heading)
    path = WaypointPath.build(t0, points, v_start, s.speed if speed_end is None else speed_end)
    speed, gamma, heading = (float(x) for x in path.end_state())
    return Planned((path,), path.duration, KinematicState(speed, gamma, heading))


SEGMENT_KINDS = {
    "static": SegmentKind(_parse_duration, _plan_static),
    "cruise": SegmentKind(_parse_duration, _plan_cruise),
    "accelerate": SegmentKind(_parse_accelerate, _plan_accelerate),
    "turn": SegmentKind(_parse_turn, _plan_turn),
    "climb": SegmentKind(_parse_climb, _plan_pitch_to),
    "pullup": SegmentKind(_parse_pullup, _plan_pullup),
    "roll": SegmentKind(_parse_roll, _plan_roll),
    "loop": SegmentKind(_parse_loop, _plan_loop),
    "weave": SegmentKind(_parse_weave, _plan_weave),
    "rates": SegmentKind(_parse_rates, _plan_rates),
    "waypoints": SegmentKind(_parse_waypoints, _plan_waypoints),
}
KINDS = tuple(SEGMENT_KINDS)
