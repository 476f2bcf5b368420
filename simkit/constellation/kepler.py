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
KEPLER_MAX_ITERATIONS = 30
KEPLER_STOP = 1e-14  # Newton step (rad) that ends the iteration
# calls with fewer states run on one thread: numba's thread team costs more CPU than it saves below this size, and
# on a loaded machine wall time too (docs/benchmarks.md: a GNSS block of 600 epochs x 67 satellites, 40,200
# states: 15.7 ms of CPU and 40 ms of wall on 2 threads against 9.6 ms and 23 ms on one)
PARALLEL_MIN_STATES = 1 << 17
KEPLER_TOL = 1e-13   # rad per unit |M| (RTKLIB's RTOL_KEPLER): a larger last step after 30 iterations is a failure
# column numbers as module constants (numba compiles them in; a dict lookup cannot run inside the kernel)
_TOE, _TOC, _SQRT_A, _E, _I0, _OMEGA0, _OMEGA, _M0, _DELTA_N, _IDOT, _OMEGA_DOT = (
    COL[k] for k in ("toe", "toc", "sqrt_a", "e", "i0", "omega0", "omega", "m0", "delta_n", "idot", "omega_dot"))
_CUC, _CUS, _CRC, _CRS, _CIC, _CIS, _AF0, _AF1, _AF2 = (
    COL[k] for k in ("cuc", "cus", "crc", "crs", "cic", "cis", "af0", "af1", "af2"))
_TOE_SOW, _MU, _OMEGA_E, _REL_F, _GEO = (COL[k] for k in ("toe_sow", "mu", "omega_e", "rel_f", "geo"))


def empty_table(n: int) -> np.ndarray:
    """A zeroed (n, len(FIELDS)) parameter table."""
    return np.zeros((n, len(FIELDS)))


@numba.njit(cache=True, inline="always")
def _eccentric_anomaly(m, e):
    """Kepler's equation E - e sin E = M by Newton from E = M: (E, converged). Not converged: the last step after
    KEPLER_MAX_ITERATIONS is larger than KEPLER_TOL * max(1, |M|) (a NaN M never converges)."""
    ecc_anom = m
    d = np.inf
    for _ in range(KEPLER_MAX_ITERATIONS):
        d = (ecc_anom - e * math.sin(ecc_anom) - m) / (1.0 - e * math.cos(ecc_anom))
        ecc_anom -= d
        if abs(d) < KEPLER_STOP:
            break
    return ecc_anom, abs(d) <= KEPLER_TOL * max(1.0, abs(m))


@numba.njit(cache=True, inline="always")
def _orbit(p, tk, n, ecc_anom, want_vel):
    """Position and velocity (x, y, z, vx, vy, vz) of record ``p`` at tk s from toe, for eccentric anomaly
    ``ecc_anom`` and corrected mean motion ``n``: ECEF, or for a BDS GEO the frame before the GEO rotation.
    The velocity (zeros unless ``want_vel``) is the analytic derivative of the same formulas."""
    a = p[_SQRT_A] * p[_SQRT_A]
    e = p[_E]
    s_e, c_e = math.sin(ecc_anom), math.cos(ecc_anom)
    one_m_ecos = 1.0 - e * c_e
    sq1e2 = math.sqrt(1.0 - e * e)
    phi = math.atan2(sq1e2 * s_e, c_e - e) + p[_OMEGA]
    s2, c2 = math.sin(2.0 * phi), math.cos(2.0 * phi)
    u = phi + p[_CUS] * s2 + p[_CUC] * c2
    r = a * one_m_ecos + p[_CRS] * s2 + p[_CRC] * c2
    inc = p[_I0] + p[_CIS] * s2 + p[_CIC] * c2 + p[_IDOT] * tk
    # a GEO's node is propagated without Earth rotation (the rotation comes with the GEO tilt)
    node_rate = p[_OMEGA_DOT] if p[_GEO] != 0.0 else p[_OMEGA_DOT] - p[_OMEGA_E]
    node = p[_OMEGA0] + node_rate * tk - p[_OMEGA_E] * p[_TOE_SOW]
    c_u, s_u = math.cos(u), math.sin(u)
    xp, yp = r * c_u, r * s_u
    c_o, s_o = math.cos(node), math.sin(node)
    c_i, s_i = math.cos(inc), math.sin(inc)
    x = xp * c_o - yp * c_i * s_o
    y = xp * s_o + yp * c_i * c_o
    z = yp * s_i
    if not want_vel:
        return x, y, z, 0.0, 0.0, 0.0
    e_dot = n / one_m_ecos
    phi_dot = e_dot * sq1e2 / one_m_ecos
    u_dot = phi_dot * (1.0 + 2.0 * (p[_CUS] * c2 - p[_CUC] * s2))
    r_dot = a * e * s_e * e_dot + 2.0 * phi_dot * (p[_CRS] * c2 - p[_CRC] * s2)
    i_dot = p[_IDOT] + 2.0 * phi_dot * (p[_CIS] * c2 - p[_CIC] * s2)
    xp_dot = r_dot * c_u - yp * u_dot
    yp_dot = r_dot * s_u + xp * u_dot
    vx = xp_dot * c_o - yp_dot * c_i * s_o + yp * s_i * s_o * i_dot - y * node_rate
    vy = xp_dot * s_o + yp_dot * c_i * c_o - yp * s_i * c_o * i_dot + x * node_rate
    vz = yp_dot * s_i + yp * c_i * i_dot
    return x, y, z, vx, vy, vz


@numba.njit(cache=True, inline="always")
def _geo_rotation(x, y, z, vx, vy, vz, om_e, tk, want_vel):
    """BDS GEO: R_X(-5 deg) then R_Z(Omega_e tk), both as defined in the BDS ICD (velocity with the frame rate)."""
    c_tilt, s_tilt = math.cos(GEO_TILT), math.sin(GEO_TILT)
    y1 = c_tilt * y + s_tilt * z
    z1 = -s_tilt * y + c_tilt * z
    c_t, s_t = math.cos(om_e * tk), math.sin(om_e * tk)
    gx = c_t * x + s_t * y1
    gy = -s_t * x + c_t * y1
    if not want_vel:
        return gx, gy, z1, 0.0, 0.0, 0.0
    vy1 = c_tilt * vy + s_tilt * vz
    vz1 = -s_tilt * vy + c_tilt * vz
    return gx, gy, z1, c_t * vx + s_t * vy1 + om_e * gy, -s_t * vx + c_t * vy1 - om_e * gx, vz1


@numba.njit(cache=True, inline="always")
def _propagate_one(params, idx, t, want_vel, pos, clk, vel, drift, k):
    if idx[k] < 0:  # no valid record
        _store_nan(k, want_vel, pos, clk, vel, drift)
        return
    p = params[idx[k]]
    tk = t[k] - p[_TOE]
    a = p[_SQRT_A] * p[_SQRT_A]
    n = math.sqrt(p[_MU] / (a * a * a)) + p[_DELTA_N]
    ecc_anom, converged = _eccentric_anomaly(p[_M0] + n * tk, p[_E])
    if not converged:
        _store_nan(k, want_vel, pos, clk, vel, drift)
        return
    x, y, z, vx, vy, vz = _orbit(p, tk, n, ecc_anom, want_vel)
    if p[_GEO] != 0.0:
        x, y, z, vx, vy, vz = _geo_rotation(x, y, z, vx, vy, vz, p[_OMEGA_E], tk, want_vel)
    dtc = t[k] - p[_TOC]
    rel = p[_REL_F] * p[_E] * p[_SQRT_A]
    clock = p[_AF0] + p[_AF1] * dtc + p[_AF2] * dtc * dtc + rel * math.sin(ecc_anom)
    c_e = math.cos(ecc_anom)
    rate = p[_AF1] + 2.0 * p[_AF2] * dtc + rel * c_e * (n / (1.0 - p[_E] * c_e))
    _store(k, x, y, z, clock, vx, vy, vz, rate, want_vel, pos, clk, vel, drift)


@numba.njit(cache=True, nogil=True, parallel=True)
def _propagate(params, idx, t, want_vel, pos, clk, vel, drift):
    for k in numba.prange(idx.shape[0]):  # independent elements: results do not depend on the thread count
        _propagate_one(params, idx, t, want_vel, pos, clk, vel, drift, k)


@numba.njit(cache=True, nogil=True)
def _propagate_serial(params, idx, t, want_vel, pos, clk, vel, drift):
    for k in range(idx.shape[0]):
        _propagate_one(params, idx, t, want_vel, pos, clk, vel, drift, k)


@numba.njit(cache=True, inline="always")
def _store(k, x, y, z, clock, vx, vy, vz, rate, want_vel, pos, clk, vel, drift):
    pos[k, 0], pos[k, 1], pos[k, 2] = x, y, z
    clk[k] = clock
    if want_vel:
        vel[k, 0], vel[k, 1], vel[k, 2] = vx, vy, vz
        drift[k] = rate


@numba.njit(cache=True, inline="always")
def _store_nan(k, want_vel, pos, clk, vel, drift):
    _store(k, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, want_vel, pos, clk, vel, drift)


def propagate(params: np.ndarray, idx: np.ndarray, t: np.ndarray, velocity: bool = False):
    """Evaluate records ``params[idx]`` at times ``t`` (GPS seconds since the reference week), both (N,).

    Returns ``pos`` (N, 3) m ECEF, ``clk`` (N,) s, and when ``velocity`` also ``vel`` (N, 3) m/s ECEF and
    ``drift`` (N,) s/s. Entries with ``idx < 0`` are NaN, and so are those where Kepler's equation did not
    converge within ``KEPLER_MAX_ITERATIONS`` Newton steps (only near-parabolic eccentricities; never for
    GNSS orbits).
    """
    idx = np.ascontiguousarray(idx, dtype=np.int64)
    t = np.ascontiguousarray(t, dtype=float)
    n = idx.shape[0]
    pos = np.empty((n, 3))
    clk = np.empty(n)
    vel = np.empty((n, 3) if velocity else (0, 3))
    drift = np.empty(n if velocity else 0)
    kernel = _propagate if n >= PARALLEL_MIN_STATES else _propagate_serial
    kernel(np.ascontiguousarray(params), idx, t, velocity, pos, clk, vel, drift)
    return (pos, clk, vel, drift) if velocity else (pos, clk)
