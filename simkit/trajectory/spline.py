"""Waypoint segments: a 7th-order spline through positions, turned into speed / flight-path / heading commands.

The spline is built in the local ENU tangent plane at the point where the segment begins, with clamped velocity
and zero acceleration and jerk at both ends, so commands join the neighbouring segments smoothly (C1 turn rate).
The generator integrates the commands on the ellipsoid, so the flown path departs from the tangent-plane spline by
the Earth's curvature and the meridian convergence (each about d^2 / 2R: 0.8 m after 3.2 km, 8 m after 10 km).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def unit_velocity(gamma, psi):
    """Unit vector of flight-path angle ``gamma`` and heading ``psi`` (clockwise from north) in ENU."""
    return np.array([np.cos(gamma) * np.sin(psi), np.cos(gamma) * np.cos(psi), np.sin(gamma)])


@dataclass
class WaypointPath:
    """Spline through ``points`` (ENU, m, first point = segment start) at the given node times."""

    start: float
    times: np.ndarray
    spline: object

    @classmethod
    def build(cls, start, points, v_start, speed_end):
        """``v_start``: entry velocity (ENU m/s); ``speed_end``: exit speed; exit direction along the last leg."""
        from scipy.interpolate import make_interp_spline  # here: only waypoint segments need scipy.interpolate

        pts = np.vstack([np.zeros(3), np.asarray(points, dtype=float)])
        legs = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        v0 = float(np.linalg.norm(v_start))
        mean_speed = 0.5 * (v0 + speed_end)
        times = np.concatenate([[0.0], np.cumsum(legs / mean_speed)])
        direction = (pts[-1] - pts[-2]) / legs[-1]
        zero = np.zeros(3)
        bc = ([(1, np.asarray(v_start, float)), (2, zero), (3, zero)],
              [(1, speed_end * direction), (2, zero), (3, zero)])
        return cls(start, times, make_interp_spline(times, pts, k=7, bc_type=bc))

    @property
    def duration(self) -> float:
        return float(self.times[-1])

    @property
    def end(self) -> float:
        return self.start + self.duration

    def end_state(self):
        """(speed, flight-path angle, heading) at the end of the path."""
        return self._kinematics(np.array([self.duration]))[0][:, 0]

    def _kinematics(self, tau):
        v = self.spline(tau, 1)
        a = self.spline(tau, 2)
        j = self.spline(tau, 3)
        ve, vn, vu = v.T
        ae, an, au = a.T
        je, jn = j[:, 0], j[:, 1]
        vh2 = ve**2 + vn**2
        vh = np.sqrt(vh2)
        speed = np.sqrt(vh2 + vu**2)
        vh_dot = (ve * ae + vn * an) / vh
        speed_dot = (ve * ae + vn * an + vu * au) / speed
        gamma = np.arctan2(vu, vh)
        gamma_dot = (au * vh - vu * vh_dot) / speed**2
        cross = vn * ae - ve * an
        psi = np.arctan2(ve, vn)
        psi_dot = cross / vh2
        psi_ddot = ((vn * je - ve * jn) * vh2 - cross * 2.0 * (ve * ae + vn * an)) / vh2**2
        return np.array([speed, gamma, psi]), dict(
            accel=speed_dot, pitch_rate=gamma_dot, turn_rate=psi_dot, turn_accel=psi_ddot)

    def commands(self, t):
        """Channel values at absolute times ``t``: dict of arrays, zero outside the segment."""
        t = np.asarray(t, dtype=float)
        inside = (t >= self.start) & (t <= self.end)
        out = {k: np.zeros_like(t) for k in ("accel", "pitch_rate", "turn_rate", "turn_accel")}
        if inside.any():
            _, ch = self._kinematics(t[inside] - self.start)
            for k, v in ch.items():
                out[k][inside] = v
        return out
