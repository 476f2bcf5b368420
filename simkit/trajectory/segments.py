"""Motion segments: parsing ``[[trajectory.segment]]`` tables and planning them into command profiles.

Kinematic channels (all in the local-level ENU frame at the vehicle):
``accel`` = dV/dt (m/s^2, along the velocity), ``pitch_rate`` = d(gamma)/dt (flight-path angle rate, rad/s),
``turn_rate`` = d(psi)/dt (heading rate, clockwise positive, rad/s) with ``turn_accel`` its derivative, and
``roll_rate`` (rad/s, roll about body y added to any coordinated bank). Positive turn angles turn right.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..section import Section, positive
from .profiles import Plateau, Sinusoid
from .spline import WaypointPath, unit_velocity

G0 = 9.80665  # standard gravity, m/s^2: load factors and the coordinated-bank law use it

KINDS = ("static", "cruise", "accelerate", "turn", "climb", "pullup", "roll", "loop", "weave", "rates", "waypoints")


@dataclass
class Channel:
    """One smooth profile feeding one kinematic channel."""

    name: str
    profile: object

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


@dataclass
class KinematicState:
    """What the planner tracks across segments: speed (m/s), flight-path angle and heading (rad)."""

    speed: float
    gamma: float
    heading: float


def plan(sections: list[Section], state: KinematicState, default_ramp: float):
    """Turn segment tables into (list of channel/path objects with .start/.end/.commands, end time)."""
    items, t = [], 0.0
    for sec in sections:
        new, duration = _plan_one(sec, t, state, default_ramp)
        sec.done()
        items.extend(new)
        t += duration
    return items, t


def _turn_sign(sec: Section) -> float:
    direction = sec.get("direction", str, "right", choices=("right", "left"))
    return 1.0 if direction == "right" else -1.0


def _need_speed(sec: Section, state: KinematicState, kind: str):
    if state.speed <= 0.0:
        raise sec.error("kind", f"'{kind}' needs a moving vehicle, but the speed here is 0 m/s: accelerate first")


def _plan_one(sec: Section, t0: float, s: KinematicState, default_ramp: float):
    kind = sec.get("kind", str, choices=KINDS)
    ramp = sec.get("ramp_s", float, default_ramp, check=positive)
    rad = np.radians

    if kind in ("static", "cruise"):
        duration = sec.get("duration_s", float, check=positive)
        if kind == "static" and s.speed != 0.0:
            raise sec.error("kind", f"'static' needs speed 0, but the vehicle moves at {s.speed:g} m/s here")
        return [], duration

    if kind == "accelerate":
        accel = sec.get("accel_m_per_s2", float, check=positive)
        if sec.has("target_speed_m_per_s"):
            target = sec.get("target_speed_m_per_s", float, check=lambda v: None if v >= 0 else "must be >= 0")
            p = Plateau.for_change(t0, target - s.speed, accel, ramp)
        else:
            duration = sec.get("duration_s", float, check=positive)
            sign = -1.0 if sec.get("direction", str, "faster", choices=("faster", "slower")) == "slower" else 1.0
            p = Plateau(t0, duration, min(ramp, duration / 2), sign * accel)
        s.speed += p.value * (p.duration - p.ramp)
        if s.speed < -1e-9:
            raise sec.error("duration_s", f"decelerates below zero speed ({s.speed:.3g} m/s at the end)")
        s.speed = max(s.speed, 0.0)
        return [Channel("accel", p)], p.duration

    if kind == "turn":
        _need_speed(sec, s, kind)
        given = [k for k in ("rate_deg_per_s", "radius_m", "load_factor_g") if sec.has(k)]
        if len(given) != 1:
            raise sec.error("rate_deg_per_s", "give exactly one of rate_deg_per_s, radius_m, load_factor_g")
        horizontal = s.speed * np.cos(s.gamma)
        if given[0] == "rate_deg_per_s":
            rate = rad(sec.get("rate_deg_per_s", float, check=lambda v: None if v != 0 else "must be non-zero"))
        elif given[0] == "radius_m":
            rate = horizontal / sec.get("radius_m", float, check=positive)
        else:
            n = sec.get("load_factor_g", float, check=lambda v: None if v > 1 else "must be > 1")
            rate = G0 * np.sqrt(n * n - 1.0) / horizontal
        if sec.has("angle_deg"):
            angle = rad(sec.get("angle_deg", float, check=lambda v: None if v != 0 else "must be non-zero"))
            if given[0] != "rate_deg_per_s":
                rate = abs(rate) * np.sign(angle)
            elif np.sign(rate) != np.sign(angle):
                raise sec.error("angle_deg", "has the opposite sign of rate_deg_per_s")
            p = Plateau.for_change(t0, angle, rate, ramp)
        else:
            duration = sec.get("duration_s", float, check=positive)
            if given[0] != "rate_deg_per_s":
                rate = abs(rate) * _turn_sign(sec)
            p = Plateau(t0, duration, min(ramp, duration / 2), rate)
        s.heading += p.value * (p.duration - p.ramp)
        return [Channel("turn_rate", p)], p.duration

    if kind in ("climb", "pullup"):
        _need_speed(sec, s, kind)
        target = rad(sec.get("flight_path_deg", float, check=lambda v: None if -90 < v < 90 else "must be in (-90, 90)"))
        if kind == "climb":
            rate = rad(sec.get("pitch_rate_deg_per_s", float, 3.0, check=positive))
        else:
            n = sec.get("load_factor_g", float, check=lambda v: None if v > 1 else "must be > 1")
            rate = G0 * (n - 1.0) / s.speed
        p = Plateau.for_change(t0, target - s.gamma, rate, ramp)
        s.gamma = target
        return ([Channel("pitch_rate", p)] if p.duration > 0 else []), p.duration

    if kind == "roll":
        rate = rad(sec.get("rate_deg_per_s", float, check=lambda v: None if v != 0 else "must be non-zero"))
        rolls = sec.get("rolls", float, 1.0, check=positive)
        p = Plateau.for_change(t0, np.sign(rate) * 2.0 * np.pi * rolls, rate, ramp)
        return [Channel("roll_rate", p)], p.duration

    if kind == "loop":
        _need_speed(sec, s, kind)
        if sec.has("radius_m") == sec.has("load_factor_g"):
            raise sec.error("radius_m", "give exactly one of radius_m, load_factor_g")
        if sec.has("radius_m"):
            rate = s.speed / sec.get("radius_m", float, check=positive)
        else:
            rate = G0 * (sec.get("load_factor_g", float, check=lambda v: None if v > 1 else "must be > 1") - 1) / s.speed
        loops = sec.get("loops", float, 1.0, check=positive)
        p = Plateau.for_change(t0, 2.0 * np.pi * loops, rate, ramp)
        s.gamma = float(np.angle(np.exp(1j * (s.gamma + p.value * (p.duration - p.ramp)))))
        return [Channel("pitch_rate", p)], p.duration

    if kind == "weave":
        _need_speed(sec, s, kind)
        period = sec.get("period_s", float, check=positive)
        cycles = sec.get("cycles", float, 1.0, check=positive)
        if sec.has("heading_amplitude_deg") == sec.has("rate_amplitude_deg_per_s"):
            raise sec.error("heading_amplitude_deg", "give exactly one of heading_amplitude_deg, rate_amplitude_deg_per_s")
        if sec.has("heading_amplitude_deg"):
            amp = rad(sec.get("heading_amplitude_deg", float, check=positive)) * 2.0 * np.pi / period
        else:
            amp = rad(sec.get("rate_amplitude_deg_per_s", float, check=positive))
        duration = period * cycles
        w = Sinusoid(t0, duration, min(ramp, duration / 2), amp, period)
        tt = np.linspace(t0, t0 + duration, 20001)
        s.heading += float(np.trapezoid(w.evaluate(tt)[0], tt))  # planning only needs it approximately
        return [Channel("turn_rate", w)], duration

    if kind == "rates":
        duration = sec.get("duration_s", float, check=positive)
        r = min(ramp, duration / 2)
        items = []
        for key, channel, scale in (("accel_m_per_s2", "accel", 1.0), ("pitch_rate_deg_per_s", "pitch_rate", np.pi / 180),
                                    ("turn_rate_deg_per_s", "turn_rate", np.pi / 180),
                                    ("roll_rate_deg_per_s", "roll_rate", np.pi / 180)):
            value = sec.get(key, float, 0.0) * scale
            if value:
                p = Plateau(t0, duration, r, value)
                items.append(Channel(channel, p))
                area = value * (duration - r)
                if channel == "accel":
                    s.speed += area
                elif channel == "pitch_rate":
                    s.gamma += area
                elif channel == "turn_rate":
                    s.heading += area
        if s.speed < -1e-9:
            raise sec.error("accel_m_per_s2", f"decelerates below zero speed ({s.speed:.3g} m/s at the end)")
        return items, duration

    # waypoints
    _need_speed(sec, s, kind)
    points = sec.get("points_enu_m", list)
    if len(points) < 1 or not all(isinstance(p, list) and len(p) == 3 and all(
            isinstance(x, (int, float)) and not isinstance(x, bool) for x in p) for p in points):
        raise sec.error("points_enu_m", f"expected an array of [east, north, up] triples in m, got {points!r}")
    pts = np.asarray(points, dtype=float)
    if np.any(np.linalg.norm(np.diff(np.vstack([np.zeros(3), pts]), axis=0), axis=1) == 0):
        raise sec.error("points_enu_m", "two consecutive waypoints coincide (the first point is the segment start)")
    speed_end = sec.get("speed_m_per_s", float, s.speed, check=positive)
    path = WaypointPath.build(t0, pts, s.speed * unit_velocity(s.gamma, s.heading), speed_end)
    s.speed, s.gamma, s.heading = (float(x) for x in path.end_state())
    return [path], path.duration
