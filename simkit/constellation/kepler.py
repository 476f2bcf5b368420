"""Keplerian broadcast-orbit kernel: positions, velocities and clocks for many (record, time) pairs at once.

Implements the IS-GPS-200 Table 20-IV user algorithm (and its BDS-SIS-ICD twin with each system's mu and
Omega_e), including the BDS GEO case (BDS-SIS-ICD-B1I 5.2.4.12): orbit in an inertial-like frame, then
R_Z(Omega_e tk) R_X(-5 deg). Velocities and clock drifts are the analytic time derivatives of the same formulas.
Almanacs and nominal orbits use the same kernel with the harmonic and rate terms set to zero.

A parameter table has one row per record, columns named in :data:`FIELDS`. Times (``toe``, ``toc`` and the
evaluation times) are GPS-time seconds since the constellation's reference week; ``toe_sow`` is toe in the
record's own system time of week (it enters the right ascension of the node).
"""
from __future__ import annotations

import math

import numba
import numpy as np

FIELDS = (
    "toe", "toc", "sqrt_a", "e", "i0", "omega0", "omega", "m0", "delta_n", "idot", "omega_dot",
    "cuc", "cus", "crc", "crs", "cic", "cis", "af0", "af1", "af2", "toe_sow", "mu", "omega_e", "rel_f", "geo",
)
COL = {name: k for k, name in enumerate(FIELDS)}
GEO_TILT = -5.0 * math.pi / 180.0


def empty_table(n: int) -> np.ndarray:
    """A zeroed (n, len(FIELDS)) parameter table."""
    return np.zeros((n, len(FIELDS)))


@numba.njit(cache=True, parallel=True)
def _propagate(params, idx, t, want_vel, pos, clk, vel, drift):
    c_tilt = math.cos(GEO_TILT)
    s_tilt = math.sin(GEO_TILT)
    for k in numba.prange(idx.shape[0]):  # independent elements: results do not depend on the thread count
        r_i = idx[k]
        if r_i < 0:
            pos[k, 0] = np.nan
            pos[k, 1] = np.nan
            pos[k, 2] = np.nan
            clk[k] = np.nan
            if want_vel:
                vel[k, 0] = np.nan
                vel[k, 1] = np.nan
                vel[k, 2] = np.nan
                drift[k] = np.nan
            continue
        p = params[r_i]
        mu = p[21]
        om_e = p[22]
        a = p[2] * p[2]
        e = p[3]
        tk = t[k] - p[0]
        n = math.sqrt(mu / (a * a * a)) + p[8]
        m = p[7] + n * tk
        ecc_anom = m
        for _ in range(30):
            d = (ecc_anom - e * math.sin(ecc_anom) - m) / (1.0 - e * math.cos(ecc_anom))
            ecc_anom -= d
            if abs(d) < 1e-14:
                break
        s_e = math.sin(ecc_anom)
        c_e = math.cos(ecc_anom)
        one_m_ecos = 1.0 - e * c_e
        sq1e2 = math.sqrt(1.0 - e * e)
        phi = math.atan2(sq1e2 * s_e, c_e - e) + p[6]
        s2 = math.sin(2.0 * phi)
        c2 = math.cos(2.0 * phi)
        u = phi + p[12] * s2 + p[11] * c2
        r = a * one_m_ecos + p[14] * s2 + p[13] * c2
        inc = p[4] + p[16] * s2 + p[15] * c2 + p[9] * tk
        geo = p[24] != 0.0
        if geo:
            node_rate = p[10]
        else:
            node_rate = p[10] - om_e
        node = p[5] + node_rate * tk - om_e * p[20]
        c_u = math.cos(u)
        s_u = math.sin(u)
        xp = r * c_u
        yp = r * s_u
        c_o = math.cos(node)
        s_o = math.sin(node)
        c_i = math.cos(inc)
        s_i = math.sin(inc)
        x = xp * c_o - yp * c_i * s_o
        y = xp * s_o + yp * c_i * c_o
        z = yp * s_i
        if want_vel:
            e_dot = n / one_m_ecos
            phi_dot = e_dot * sq1e2 / one_m_ecos
            u_dot = phi_dot * (1.0 + 2.0 * (p[12] * c2 - p[11] * s2))
            r_dot = a * e * s_e * e_dot + 2.0 * phi_dot * (p[14] * c2 - p[13] * s2)
            i_dot = p[9] + 2.0 * phi_dot * (p[16] * c2 - p[15] * s2)
            xp_dot = r_dot * c_u - yp * u_dot
            yp_dot = r_dot * s_u + xp * u_dot
            vx = xp_dot * c_o - yp_dot * c_i * s_o + yp * s_i * s_o * i_dot - y * node_rate
            vy = xp_dot * s_o + yp_dot * c_i * c_o - yp * s_i * c_o * i_dot + x * node_rate
            vz = yp_dot * s_i + yp * c_i * i_dot
        if geo:
            # R_X(-5 deg) then R_Z(Omega_e tk), both as defined in the BDS ICD
            y1 = c_tilt * y + s_tilt * z
            z1 = -s_tilt * y + c_tilt * z
            th = om_e * tk
            c_t = math.cos(th)
            s_t = math.sin(th)
            gx = c_t * x + s_t * y1
            gy = -s_t * x + c_t * y1
            x, y, z = gx, gy, z1
            if want_vel:
                vy1 = c_tilt * vy + s_tilt * vz
                vz1 = -s_tilt * vy + c_tilt * vz
                gvx = c_t * vx + s_t * vy1 + om_e * y
                gvy = -s_t * vx + c_t * vy1 - om_e * x
                vx, vy, vz = gvx, gvy, vz1
        pos[k, 0] = x
        pos[k, 1] = y
        pos[k, 2] = z
        dtc = t[k] - p[1]
        rel = p[23] * e * p[2]
        clk[k] = p[17] + p[18] * dtc + p[19] * dtc * dtc + rel * s_e
        if want_vel:
            vel[k, 0] = vx
            vel[k, 1] = vy
            vel[k, 2] = vz
            drift[k] = p[18] + 2.0 * p[19] * dtc + rel * c_e * e_dot


def propagate(params: np.ndarray, idx: np.ndarray, t: np.ndarray, velocity: bool = False):
    """Evaluate records ``params[idx]`` at times ``t`` (GPS seconds since the reference week), both (N,).

    Returns ``pos`` (N, 3) m ECEF, ``clk`` (N,) s, and when ``velocity`` also ``vel`` (N, 3) m/s ECEF and
    ``drift`` (N,) s/s. Entries with ``idx < 0`` are NaN.
    """
    idx = np.ascontiguousarray(idx, dtype=np.int64)
    t = np.ascontiguousarray(t, dtype=float)
    n = idx.shape[0]
    pos = np.empty((n, 3))
    clk = np.empty(n)
    vel = np.empty((n, 3) if velocity else (0, 3))
    drift = np.empty(n if velocity else 0)
    _propagate(np.ascontiguousarray(params), idx, t, velocity, pos, clk, vel, drift)
    return (pos, clk, vel, drift) if velocity else (pos, clk)
