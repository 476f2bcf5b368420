"""Stochastic street shadowing and blockage of C/N0: a three-state Markov channel per satellite (and antenna).

A receiver in a street sees a satellite in line of sight, shadowed (by trees, building edges, diffraction over a
roof: attenuated but tracked) or blocked (not tracked), and the state changes as the vehicle moves. Land mobile
satellite channel models describe this by a Markov chain of states with exponentially distributed state
durations expressed as distances travelled and a log-normal shadowing attenuation in the shadowed state (Lutz et
al., "The land mobile satellite communication channel - recording, statistics, and channel model", IEEE Trans. Veh.
Technol. 40(2), 1991: two states; Perez-Fontan et al., "Statistical modeling of the LMS channel using a time-series
generator", IEEE Trans. Aerosp. Electron. Syst. 37(3), 2001: three states with tables per elevation and
environment; ITU-R P.681, the state model of its land mobile section). simkit keeps the three states and their
elevation dependence (optionally a table per system: ``[gnss.shadowing.systems.<letter>]``); the parameters are the scenario's (``simkit twin --fit`` estimates them from a real drive,
docs/real_data.md); no table of the papers is built in.

The chain is a continuous-time Markov process with generator Q (per elevation bin b): stationary probabilities
pi = (pi_los, pi_shadowed, pi_blocked) of the bin and mean dwell times D_i (seconds, or metres travelled), the
exit flux of state i f_i = pi_i / D_i. It is the reversible chain with those fluxes: the flux between states i and j
F_ij = (f_i + f_j - f_k) / 2 (k the third state), Q_ij = F_ij / pi_i. Where the fluxes do not form a triangle
(f_i > f_j + f_k: the other two states cannot absorb state i's exits), F_jk = 0, F_ij = f_j, F_ik = f_k, and state i
dwells longer than D_i. One step of the chain over a time dt (or the distance travelled in it) is
P = expm(Q dt), through the eigen-decomposition of the symmetric Pi^(1/2) Q Pi^(-1/2); pi is stationary under P
and a state's mean run in steps is 1 / (1 - P_ii).

Shadowing attenuation (dB, subtracted from C/N0 in the shadowed state): mean + sigma x, x a unit Gauss-Markov
process with correlation time (or distance) tau, x_k = a x_(k-1) + sqrt(1 - a^2) w_k, a = exp(-step / tau): a
log-normal power loss. A blocked satellite is not tracked (reacquisition after the blockage follows
``[gnss.acquisition]``); the thermal noise follows the lowered C/N0.

Randomness: each chain (satellite, and antenna unless they share it) owns the stream ``gnss/shadowing/<chain>/<sat
id>`` (:mod:`simkit.rng`); epoch k owns its outputs [2k, 2k + 2) (a uniform for the transition and one for the
attenuation's innovation), and the stream jumps over the epochs it is not needed, as :mod:`.draws` does. A chain
exists at the epochs its satellite is above the horizon margin at the IMU centre; it starts in its bin's stationary
distribution (x in its stationary N(0, 1)) each time the satellite comes up. The state is carried between blocks:
the output does not depend on the block split.
"""
from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from scipy.special import ndtri

from .. import rng
from ..section import Section, non_negative

LOS, SHADOWED, BLOCKED = 0, 1, 2
NOT_EVALUATED = 255        # below the horizon margin: no chain
DRAWS_PER_EPOCH = 2
_HALF_ULP = 2.0**-54
_PI_FLOOR = 1e-9           # a state of zero probability keeps a tiny one, so Pi^(-1/2) exists
ANTENNA_MODES = ("common", "independent")
_SYSTEMS = ("G", "C", "E", "R", "J")


@dataclass(frozen=True)
class ShadowingConfig:
    """``[gnss.shadowing]``: the elevation bins' lower edges (rad, ascending; a bin runs to the next edge, the last
    to 90 deg, elevations below the first edge take the first bin), the stationary probabilities (B, 3) of (line of
    sight, shadowed, blocked) per bin, the mean dwell times (3,) in ``unit`` ("s" or "m" travelled), the
    attenuation's mean and standard deviation (dB) and correlation (in ``unit``), and whether the antennas of the
    receiver share one chain per satellite ("common": antennas a metre apart see the same street) or not."""

    elevation_edges_rad: tuple
    probabilities: tuple
    dwell: tuple
    unit: str
    attenuation_mean_db: float
    attenuation_sigma_db: float
    attenuation_correlation: float
    antennas: str = "common"
    systems: tuple = ()          # ((system letter, probabilities (B * 3,)), ...): a system's own state probabilities

    @property
    def pi(self) -> np.ndarray:
        return np.asarray(self.probabilities, float).reshape(-1, 3)

    def tables(self) -> tuple[list, np.ndarray]:
        """(system letters with their own table, [(B, 3) probabilities]: the shared table first, then theirs)."""
        return [k for k, _ in self.systems], [self.pi] + [np.asarray(p, float).reshape(-1, 3) for _, p in self.systems]


def parse_shadowing(sec: Section) -> ShadowingConfig | None:
    """Read ``[gnss.shadowing]`` (``sec`` at path "gnss.shadowing"); None when the table is absent or empty (the
    default: no shadowing, files as before)."""
    if not sec.data:
        return None
    edges = sec.get("elevation_deg", float, shape=0)
    n = len(edges)
    if n == 0 or any(b <= a for a, b in zip(edges[:-1], edges[1:])) or not -90.0 <= edges[0] < 90.0 \
            or edges[-1] >= 90.0:
        raise sec.error("elevation_deg", f"expected ascending lower bin edges in [-90, 90) deg, got {edges!r}")
    pi = _probabilities(sec, n)
    systems = sec.section("systems")
    own = []
    for letter in list(systems.data):
        if letter not in _SYSTEMS:
            raise systems.error(letter, f"unknown system (expected one of {', '.join(_SYSTEMS)})")
        sub = systems.section(letter)
        own.append((letter, tuple(x for row in _probabilities(sub, n) for x in row)))
        sub.done()
    has_s, has_m = sec.has("dwell_s"), sec.has("dwell_m")
    if has_s == has_m:
        raise sec.error("dwell_s", "expected exactly one of dwell_s (seconds) and dwell_m (metres travelled): "
                        "[line of sight, shadowed, blocked] mean state durations")
    unit = "s" if has_s else "m"
    dwell = sec.get(f"dwell_{unit}", float, shape=3)
    if any(d <= 0.0 for d in dwell):
        raise sec.error(f"dwell_{unit}", f"expected three durations > 0 [line of sight, shadowed, blocked], "
                        f"got {dwell!r}")
    mean = sec.get("attenuation_mean_db", float, check=non_negative)
    sigma = sec.get("attenuation_sigma_db", float, 0.0, check=non_negative)
    other = "m" if unit == "s" else "s"
    if sec.has(f"attenuation_correlation_{other}"):
        raise sec.error(f"attenuation_correlation_{other}", f"the dwell times are in '{unit}': give "
                        f"attenuation_correlation_{unit}")
    corr = sec.get(f"attenuation_correlation_{unit}", float, 1.0,
                   check=lambda v: None if v > 0 else "must be > 0")
    antennas = sec.get("antennas", str, "common", choices=ANTENNA_MODES)
    sec.done()
    return ShadowingConfig(elevation_edges_rad=tuple(np.radians(edges)),
                           probabilities=tuple(x for row in pi for x in row), dwell=tuple(dwell),
                           unit=unit, attenuation_mean_db=mean, attenuation_sigma_db=sigma,
                           attenuation_correlation=corr, antennas=antennas, systems=tuple(own))


def _probabilities(sec: Section, n: int) -> list:
    """[(line of sight, shadowed, blocked)] per bin from ``shadowed_probability`` and ``blocked_probability``."""
    shadowed = sec.get("shadowed_probability", float, shape=n)
    blocked = sec.get("blocked_probability", float, shape=n)
    for key, vals in (("shadowed_probability", shadowed), ("blocked_probability", blocked)):
        if any(not 0.0 <= v <= 1.0 for v in vals):
            raise sec.error(key, f"expected probabilities in [0, 1], one per elevation bin, got {vals!r}")
    if any(s + b > 1.0 + 1e-9 for s, b in zip(shadowed, blocked)):
        raise sec.error("blocked_probability", "shadowed_probability + blocked_probability must be <= 1 in every "
                        f"elevation bin, got {shadowed!r} and {blocked!r}")
    return [(max(0.0, 1.0 - s - b), s, b) for s, b in zip(shadowed, blocked)]


def fluxes(pi, dwell) -> np.ndarray:
    """The symmetric flux matrix F (3, 3) of the reversible chain (module docstring) for stationary
    probabilities ``pi`` (3,) and mean dwells ``dwell`` (3,)."""
    f = np.asarray(pi, float) / np.asarray(dwell, float)
    F = np.zeros((3, 3))
    i = int(np.argmax(f))
    j, k = [x for x in range(3) if x != i]
    if f[i] > f[j] + f[k]:
        F[i, j] = F[j, i] = f[j]
        F[i, k] = F[k, i] = f[k]
        return F
    for a, b, c in ((0, 1, 2), (0, 2, 1), (1, 2, 0)):
        F[a, b] = F[b, a] = 0.5 * (f[a] + f[b] - f[c])
    return F


def generator(pi, dwell) -> np.ndarray:
    """The generator Q (3, 3) of the chain, per unit of the dwell times."""
    pi = np.maximum(np.asarray(pi, float), _PI_FLOOR)
    q = fluxes(pi / pi.sum(), dwell) / (pi / pi.sum())[:, None]
    q[np.diag_indices(3)] = -q.sum(axis=1)
    return q


def _spectral(pi, dwell):
    """(eigenvalues (3,), eigenvectors (3, 3), pi (3,)) of Pi^(1/2) Q Pi^(-1/2) for one elevation bin."""
    p = np.maximum(np.asarray(pi, float), _PI_FLOOR)
    p = p / p.sum()
    root = np.sqrt(p)
    sym = root[:, None] * generator(p, dwell) / root[None, :]
    lam, vec = np.linalg.eigh(0.5 * (sym + sym.T))
    return np.minimum(lam, 0.0), vec, p


def transition(pi, dwell, step) -> np.ndarray:
    """One step P = expm(Q step) (3, 3) of the chain over ``step`` (in the unit of the dwell times)."""
    lam, vec, p = _spectral(pi, dwell)
    root = np.sqrt(p)
    return (vec * np.exp(lam * step)) @ vec.T * root[None, :] / root[:, None]


@numba.njit(cache=True, inline="always")
def _entry(vec, lam, pi, b, i, j, h):
    """P_ij = expm(Q h)_ij of bin b from its spectral tables (clipped at 0 against rounding)."""
    v = 0.0
    for e in range(3):
        v += vec[b, i, e] * vec[b, j, e] * np.exp(lam[b, e] * h)
    return max(v * np.sqrt(pi[b, j] / pi[b, i]), 0.0)


@numba.njit(cache=True)
def _chains(bins, step, lam, vec, pi, u, z, state, x, a_step_per_unit, out_state, out_x):
    """Run chains (M, K) epoch by epoch: ``bins`` (M, K) int (-1: no chain), ``step`` (M,) the step before each
    epoch, spectral tables per bin, uniforms ``u`` and normals ``z`` (M, K); ``state``/``x`` (K,) the carried state
    (-1: none), updated in place."""
    m, k = bins.shape
    for c in range(k):
        s, xc = state[c], x[c]
        for i in range(m):
            b = bins[i, c]
            if b < 0:
                s, xc = -1, 0.0
                out_state[i, c] = -1
                out_x[i, c] = 0.0
                continue
            if s < 0:
                r = u[i, c]
                s = 0 if r < pi[b, 0] else (1 if r < pi[b, 0] + pi[b, 1] else 2)
                xc = z[i, c]
            else:
                h = step[i]
                p0 = _entry(vec, lam, pi, b, s, 0, h)
                p1 = _entry(vec, lam, pi, b, s, 1, h)
                r = u[i, c] * (p0 + p1 + _entry(vec, lam, pi, b, s, 2, h))
                s = 0 if r < p0 else (1 if r < p0 + p1 else 2)
                a = np.exp(-h * a_step_per_unit)
                xc = a * xc + np.sqrt(1.0 - a * a) * z[i, c]
            out_state[i, c] = s
            out_x[i, c] = xc
        state[c], x[c] = s, xc


@dataclass(frozen=True)
class ShadowBlock:
    """One block's channel: ``state`` (M, A, C) uint8 (:data:`LOS`, :data:`SHADOWED`, :data:`BLOCKED`,
    :data:`NOT_EVALUATED`) and ``attenuation_db`` (M, A, C): subtracted from C/N0, 0 out of the shadowed state."""

    state: np.ndarray
    attenuation_db: np.ndarray


class Shadowing:
    """The channel of every (chain, satellite) pair over the run; ``advance`` is called block by block in order."""

    def __init__(self, cfg: ShadowingConfig, seed: int, sat_ids, n_antennas: int, dt: float):
        self.cfg, self.dt, self.n_ant = cfg, float(dt), int(n_antennas)
        chains = ["common"] if cfg.antennas == "common" else [f"ant{a}" for a in range(n_antennas)]
        self.streams = [[rng.generator(seed, "gnss", "shadowing", ch, sid) for sid in sat_ids] for ch in chains]
        n = (len(chains), len(sat_ids))
        self.position = np.zeros(n, dtype=np.int64)
        self.state = np.full(n, -1, dtype=np.int64)
        self.x = np.zeros(n)
        letters, probs = cfg.tables()
        tables = [_spectral(p, cfg.dwell) for table in probs for p in table]      # (table, bin) flattened
        self.lam = np.array([t[0] for t in tables])
        self.vec = np.array([t[1] for t in tables])
        self.pi = np.array([t[2] for t in tables])
        self.edges = np.asarray(cfg.elevation_edges_rad, float)
        # each satellite's first row in the tables: its system's own, else the shared one
        self.offset = np.array([(letters.index(sid[0]) + 1 if sid[0] in letters else 0) * self.edges.size
                                for sid in sat_ids], dtype=np.int64)

    def _uniforms(self, k0: int, m: int, cols) -> np.ndarray:
        """(2, M, chains, C) uniforms in (0, 1) of epochs k0 .. k0 + m - 1."""
        out = np.empty((DRAWS_PER_EPOCH, m, len(self.streams), len(cols)))
        for h, row in enumerate(self.streams):
            for c, s in enumerate(cols):
                gen = row[s]
                skip = k0 * DRAWS_PER_EPOCH - self.position[h, s]
                if skip < 0:
                    raise ValueError(f"epochs must be drawn in order (epoch {k0} after {self.position[h, s]})")
                gen.bit_generator.advance(int(skip))
                out[:, :, h, c] = (gen.random(m * DRAWS_PER_EPOCH) + _HALF_ULP).reshape(m, DRAWS_PER_EPOCH).T
                self.position[h, s] = (k0 + m) * DRAWS_PER_EPOCH
        return out

    def advance(self, k0: int, elevation, present, speed, cols) -> ShadowBlock:
        """The channel at epochs k0 .. k0 + M - 1 (M = ``elevation.shape[0]``) for satellite columns ``cols`` (C,):
        ``elevation`` (M, C) rad at the IMU centre selects each epoch's bin, ``present`` (M, C) bool where a chain
        exists (the satellite above the horizon margin), ``speed`` (M,) m/s (for dwell times in metres)."""
        cols = np.asarray(cols, dtype=np.int64)
        m = elevation.shape[0]
        nch = len(self.streams)
        # chains of satellites that are not candidates in this block end: they restart when they come up
        off = np.ones(self.state.shape[1], dtype=bool)
        off[cols] = False
        self.state[:, off] = -1
        u = self._uniforms(k0, m, cols)
        b = np.clip(np.searchsorted(self.edges, np.nan_to_num(elevation, nan=-10.0), side="right") - 1, 0, None)
        bins = np.where(present, b + self.offset[cols][None, :], -1).astype(np.int64)
        bins = np.ascontiguousarray(np.broadcast_to(bins[:, None, :], (m, nch, cols.size)).reshape(m, -1))
        step = np.full(m, self.dt) if self.cfg.unit == "s" else np.abs(np.asarray(speed, float)) * self.dt
        st, x = self.state[:, cols].reshape(-1).copy(), self.x[:, cols].reshape(-1).copy()
        out_s = np.empty(bins.shape, dtype=np.int64)
        out_x = np.empty(bins.shape)
        _chains(bins, np.ascontiguousarray(step, dtype=float), self.lam, self.vec, self.pi,
                np.ascontiguousarray(u[0].reshape(m, -1)), ndtri(u[1].reshape(m, -1)), st, x,
                1.0 / self.cfg.attenuation_correlation, out_s, out_x)
        self.state[:, cols], self.x[:, cols] = st.reshape(nch, -1), x.reshape(nch, -1)
        out_s, out_x = out_s.reshape(m, nch, -1), out_x.reshape(m, nch, -1)
        if nch == 1:
            out_s = np.broadcast_to(out_s, (m, self.n_ant, cols.size))
            out_x = np.broadcast_to(out_x, (m, self.n_ant, cols.size))
        att = np.where(out_s == SHADOWED,
                       self.cfg.attenuation_mean_db + self.cfg.attenuation_sigma_db * out_x, 0.0)
        return ShadowBlock(state=np.where(out_s < 0, NOT_EVALUATED, out_s).astype(np.uint8), attenuation_db=att)
