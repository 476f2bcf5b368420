"""The trajectory generator: integrates the segment commands into exact, mutually consistent truth.

State: speed V, flight-path angle gamma, heading psi (clockwise from north), extra roll phi_x, and geodetic
position. The commands (dV/dt, d(gamma)/dt, d(psi)/dt, d2(psi)/dt2, roll rate) are analytic functions of time, so
V, gamma, psi, phi_x and the position are integrated with Simpson's rule on the sample grid plus midpoints (local
error h^5 f''''/2880, below 1e-12 rad per step at 1 kHz), and everything else is formed analytically from them:

- velocity v^n = V [cos(gamma) sin(psi), cos(gamma) cos(psi), sin(gamma)] (ENU, relative to Earth);
- attitude C_b^n = R_z(-psi) R_x(gamma) R_y(phi), body y along the velocity, phi = coordinated bank + phi_x with
  the coordinated bank atan(V psi' cos(gamma) / g0) (zero lateral specific force in a level turn);
- body rate w_ib^b = w_nb^b (from the Euler rates) + C_n^b (w_ie^n + w_en^n);
- specific force f^b = C_n^b (dv^n/dt + (2 w_ie^n + w_en^n) x v^n - g^n) with WGS-84 normal gravity.
Position: dh/dt = v_U, dlat/dt = v_N / (R_M + h) (fixed-point iteration, it converges in two passes),
dlon/dt = v_E / ((R_N + h) cos lat).
"""
from __future__ import annotations

from typing import Iterator

import numpy as np

from .. import earth, frames
from ..earth import G0
from .config import TrajectoryConfig
from .truth import TrajectoryTruth, Trig, body_truth, sin_cos, trig

CHANNELS = ("accel", "pitch_rate", "turn_rate", "turn_accel", "roll_rate")


def _simpson_steps(f_nodes, f_mid, h):
    """Integrals over each interval [t_k, t_k+1] and over its first half, from node and midpoint values."""
    full = h / 6.0 * (f_nodes[:-1] + 4.0 * f_mid + f_nodes[1:])
    half = h / 24.0 * (5.0 * f_nodes[:-1] + 8.0 * f_mid - f_nodes[1:])
    return full, half


def _cumulative(x0, f_nodes, f_mid, h):
    """Values at nodes (n+1) and midpoints (n) of x0 + integral of f, f given at nodes and midpoints.

    The same quadratic-per-interval rule as ``scipy.integrate.cumulative_simpson`` on the interleaved
    node/midpoint grid (which agrees to roundoff), kept by hand because it is about 10x faster (figures in
    docs/benchmarks.md).
    """
    full, half = _simpson_steps(f_nodes, f_mid, h)
    nodes = x0 + np.concatenate([[0.0], np.cumsum(full)])
    return nodes, nodes[:-1] + half


class Trajectory:
    """Truth generator for one ``[trajectory]`` configuration over ``duration_s`` seconds."""

    def __init__(self, config: TrajectoryConfig, duration_s: float):
        self.cfg = config
        self.duration_s = float(duration_s)

    def n_samples(self, rate_hz: float | None = None) -> int:
        rate = rate_hz or self.cfg.rate_hz
        return int(np.floor(self.duration_s * rate + 1e-9)) + 1

    def _commands(self, t: np.ndarray) -> dict[str, np.ndarray]:
        """The channels at the increasing times ``t``: each segment evaluated only over its support (plus one
        sample either side, against the rounding of start + duration; it is zero outside)."""
        out = {c: np.zeros_like(t) for c in CHANNELS}
        if t.size == 0:
            return out
        lo, hi = t[0], t[-1]
        for item in self.cfg.segments:
            if item.end < lo or item.start > hi:
                continue
            i0 = max(int(np.searchsorted(t, item.start)) - 1, 0)
            i1 = int(np.searchsorted(t, item.end, side="right")) + 1
            for name, value in item.commands(t[i0:i1]).items():
                out[name][i0:i1] += value
        return out

    def blocks(self, rate_hz: float | None = None, block_samples: int = 1 << 16) -> Iterator[TrajectoryTruth]:
        """Truth at ``rate_hz`` (default the trajectory rate) in consecutive blocks of ``block_samples``."""
        rate = float(rate_hz or self.cfg.rate_hz)
        h = 1.0 / rate
        n_total = self.n_samples(rate)
        if self.cfg.path is not None:                       # a logged trajectory: evaluated, not integrated
            for k0 in range(0, n_total, block_samples):
                yield self.cfg.path.truth(np.arange(k0, min(n_total, k0 + block_samples)) * h)
            return
        c = self.cfg
        state = np.array([c.speed_m_per_s, c.flight_path_rad, c.heading_rad, c.roll_rad, c.lat_rad, c.lon_rad, c.height_m])
        # every block holds block_samples samples (the writer's chunks: no block straddles two), the first one
        # from sample 0, each later one integrated from the last sample of the one before
        k0 = 0
        k1 = min(block_samples - 1, n_total - 1)
        truth, state = self._integrate(np.arange(k0, k1 + 1) * h, h, state, skip=0)
        yield truth
        while k1 < n_total - 1:
            k0, k1 = k1, min(k1 + block_samples, n_total - 1)
            truth, state = self._integrate(np.arange(k0, k1 + 1) * h, h, state, skip=1)
            yield truth

    def _integrate(self, t, h, state, skip: int):
        """Integrate from ``state`` at t[0] over the nodes ``t``; returns the truth at the nodes from ``skip`` on
        and the state at t[-1]."""
        cn = self._commands(t)
        speed, gamma, psi, rollx, g_t, p_t, (ve, vn, vu), hgt, lat, sl, cl, rn, lon = self._states(t, h, state, cn)
        k = slice(skip, None)  # views: the truth is formed sample by sample
        truth = self._assemble(t[k], {name: v[k] for name, v in cn.items()}, speed[k],
                               Trig(*(x[k] for x in g_t)), Trig(*(x[k] for x in p_t)), rollx[k],
                               (ve[k], vn[k], vu[k]), lat[k], sl[k], cl[k], rn[k], lon[k], hgt[k])
        end = np.array([speed[-1], gamma[-1], psi[-1], rollx[-1], lat[-1], lon[-1], hgt[-1]])
        return truth, end

    def _states(self, t, h, state, cn):
        """The integrated states at the nodes ``t`` from ``state`` at t[0], with the commands ``cn`` there: speed,
        gamma, psi, extra roll, trig(gamma), trig(psi), the E, N, U velocity, height, latitude with its sine and
        cosine, R_N, longitude. The midpoint values live only here, so they are freed before the block is
        assembled (its memory peak 47 MB at 65,536 samples, against 60 MB when they lived on)."""
        v0, g0_, p0, r0, lat0, lon0, h0 = state
        cm = self._commands(t[:-1] + 0.5 * h)
        speed, speed_m = _cumulative(v0, cn["accel"], cm["accel"], h)
        gamma, gamma_m = _cumulative(g0_, cn["pitch_rate"], cm["pitch_rate"], h)
        psi, psi_m = _cumulative(p0, cn["turn_rate"], cm["turn_rate"], h)
        rollx, _ = _cumulative(r0, cn["roll_rate"], cm["roll_rate"], h)

        g_t, p_t = trig(gamma), trig(psi)            # at the nodes: shared with the attitude (half angles)
        ve, vn, vu = speed * g_t.cos * p_t.sin, speed * g_t.cos * p_t.cos, speed * g_t.sin
        (sg_m, cg_m), (sp_m, cp_m) = sin_cos(gamma_m), sin_cos(psi_m)
        ve_m, vn_m, vu_m = speed_m * cg_m * sp_m, speed_m * cg_m * cp_m, speed_m * sg_m
        hgt, hgt_m = _cumulative(h0, vu, vu_m, h)
        rm, _ = earth.radii(lat0)    # the first pass from lat0 everywhere: one radius
        lat, lat_m = _cumulative(lat0, vn / (rm + hgt), vn_m / (rm + hgt_m), h)
        for _ in range(2):
            rm, _ = earth.radii(lat, sin_cos(lat)[0])
            rm_m, _ = earth.radii(lat_m, sin_cos(lat_m)[0])
            lat, lat_m = _cumulative(lat0, vn / (rm + hgt), vn_m / (rm_m + hgt_m), h)
        (sl, cl), (sl_m, cl_m) = sin_cos(lat), sin_cos(lat_m)
        _, rn = earth.radii(lat, sl)
        _, rn_m = earth.radii(lat_m, sl_m)
        lon, _ = _cumulative(lon0, ve / ((rn + hgt) * cl), ve_m / ((rn_m + hgt_m) * cl_m), h)
        return speed, gamma, psi, rollx, g_t, p_t, (ve, vn, vu), hgt, lat, sl, cl, rn, lon

    def _assemble(self, t, cmd, speed, gamma: Trig, psi: Trig, rollx, vel, lat, sin_lat, cos_lat, rn, lon,
                  hgt) -> TrajectoryTruth:
        """The truth block from the integrated states; ``vel``: the E, N, U velocity components, (N,) m/s each."""
        gamma_dot, psi_dot = cmd["pitch_rate"], cmd["turn_rate"]
        cg, sg, cp, sp = gamma.cos, gamma.sin, psi.cos, psi.sin
        if self.cfg.coordinated_turns:
            num = speed * psi_dot * cg
            num_dot = (cmd["accel"] * psi_dot * cg + speed * cmd["turn_accel"] * cg - speed * psi_dot * sg * gamma_dot)
            bank = np.arctan(num / G0)
            bank_dot = G0 * num_dot / (G0**2 + num**2)
        else:
            bank = bank_dot = np.zeros_like(t)
        roll = bank + rollx
        roll_dot = bank_dot + cmd["roll_rate"]

        accel, v_gamma, v_psi = cmd["accel"], speed * gamma_dot, speed * psi_dot  # dv/dt = a u_v + V d(u_v)/dt
        acc = (accel * (cg * sp) + v_gamma * (-sg * sp) + v_psi * (cg * cp),
               accel * (cg * cp) + v_gamma * (-sg * cp) + v_psi * (-cg * sp),
               accel * sg + v_gamma * cg)

        # earth.earth_rate_enu and f^n = dv/dt + (2 w_ie + w_en) x v - g^n, by component
        ve, vn, vu = vel
        w_ie_n, w_ie_u = earth.OMEGA_E * cos_lat, earth.OMEGA_E * sin_lat
        w_en = earth.transport_rate(lat, hgt, ve, vn, sin_lat)
        o_e, o_n, o_u = w_en[0], 2.0 * w_ie_n + w_en[1], 2.0 * w_ie_u + w_en[2]
        f_n = (acc[0] + (o_n * vu - o_u * vn), acc[1] + (o_u * ve - o_e * vu),
               acc[2] + (o_e * vn - o_n * ve) + earth.normal_gravity(lat, hgt, sin_lat))
        w_in = (w_en[0], w_ie_n + w_en[1], w_ie_u + w_en[2])
        quat_nb, euler, omega_ib_b, f_ib_b = body_truth(gamma, trig(roll), psi, (gamma_dot, roll_dot, psi_dot),
                                                        w_in, f_n)

        pos_lla = np.stack([lat, lon, hgt], axis=-1)
        r_cos = (rn + hgt) * cos_lat  # geodetic -> ECEF with the prime-vertical radius rn at hand
        s_lon, c_lon = sin_cos(lon)
        pos_ecef = np.stack([r_cos * c_lon, r_cos * s_lon, (rn * (1.0 - earth.E2) + hgt) * sin_lat], -1)
        return TrajectoryTruth(t=t, pos_ecef=pos_ecef, pos_lla=pos_lla, vel_enu=np.stack(vel, axis=-1),
                               quat_nb=quat_nb, euler=euler, omega_ib_b=omega_ib_b, f_ib_b=f_ib_b)
