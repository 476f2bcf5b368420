"""Statistics that compare a real receiver's observations with its simulated twin, computed the same way on both.

Every function takes plain arrays of one antenna: ``obs`` {kind: {signal: (M, S)}} with kinds code (m), carrier
(cycles), doppler (Hz), cn0 (dB-Hz), lli (RINEX flags); elevations (M, S) rad; epochs ``t`` (M,) s.

* Tracking: a satellite-epoch is tracked when any signal has code or carrier; visibility agreement is the share of
  satellite-epochs above the mask where real and twin agree on tracked / not tracked.
* Code noise and multipath from the code-minus-carrier: with two frequencies of a system, the ionosphere-free
  multipath combination MP_i = P_i - (1 + 2/(a-1)) L_i + (2/(a-1)) L_j, a = (f_i/f_j)^2, L in metres (Estey &
  Meertens 1999, the TEQC MP1/MP2); with one frequency P - L detrended per arc (the ionosphere's 2 I drift
  removed to first order). Either is made zero-mean per continuous arc (the ambiguity); arcs break at a gap, a
  loss-of-lock flag or a jump over ``JUMP_M``, and arcs under ``MIN_ARC`` epochs are left out.
* Carrier noise: the third time difference of the geometry-free phase L_i - L_j per arc; for white phase noise
  its variance is 20 (s_i^2 + s_j^2), so std / sqrt(20) is the combined carrier noise of the two signals (m).
* Doppler noise: D plus the carrier phase rate (D = -dL/dt / lambda) by central differences, std (robust, 1.4826 MAD), in Hz.
* Slips: loss-of-lock flags (bit 0) that are not an acquisition, per tracked hour.
"""
from __future__ import annotations

import numpy as np

from ..constellation.geometry import lines_of_sight_enu
from ..earth import C_LIGHT

ELEVATION_EDGES_DEG = np.arange(0.0, 91.0, 10.0)
JUMP_M = 10.0
MIN_ARC = 5


def elevations(sat_pos_ecef, rx_ecef) -> np.ndarray:
    """Elevations (M, S) rad of satellites (M, S, 3) m seen from a fixed receiver (3,) m ECEF (NaN without orbit)."""
    rx = np.broadcast_to(np.asarray(rx_ecef, float), (sat_pos_ecef.shape[0], 3))
    with np.errstate(invalid="ignore"):
        return lines_of_sight_enu(rx, sat_pos_ecef)[1]


def tracked(obs) -> np.ndarray:
    """(M, S) True where any signal has code or carrier."""
    out = None
    for kind in ("code", "carrier"):
        for a in obs.get(kind, {}).values():
            f = np.isfinite(a)
            out = f if out is None else out | f
    return out


def robust_std(x) -> float:
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if x.size < 3:
        return float("nan")
    return float(1.4826 * np.median(np.abs(x - np.median(x))))


def by_elevation(values, el, edges_deg=ELEVATION_EDGES_DEG, stat="mean", min_count=10) -> list:
    """``stat`` ("mean", "std", "rms" or "robust_std") of ``values`` (M, S) in elevation bins (edges in deg); None
    where a bin has fewer than ``min_count`` finite values."""
    el_deg = np.degrees(el)
    out = []
    for lo, hi in zip(edges_deg[:-1], edges_deg[1:]):
        x = values[(el_deg >= lo) & (el_deg < hi) & np.isfinite(values)]
        if x.size < min_count:
            out.append(None)
        elif stat == "mean":
            out.append(float(np.mean(x)))
        elif stat == "std":
            out.append(float(np.std(x)))
        elif stat == "rms":
            out.append(float(np.sqrt(np.mean(x ** 2))))
        else:
            out.append(robust_std(x))
    return out


def arcs(valid, lli, t, series=None, interval=None) -> np.ndarray:
    """Arc labels (M, S) int (-1 where not valid): a new arc at a gap (> 1.5 intervals), a loss-of-lock flag, or a
    jump of ``series`` over JUMP_M."""
    m, s = valid.shape
    dt = np.diff(t)
    interval = interval or (float(np.median(dt)) if dt.size else 1.0)
    gap = np.concatenate([[True], dt > 1.5 * interval])
    start = valid & (np.concatenate([np.ones((1, s), bool), ~valid[:-1]]) | gap[:, None] | ((lli & 1) != 0))
    if series is not None:
        jump = np.zeros((m, s), bool)
        with np.errstate(invalid="ignore"):
            jump[1:] = np.abs(np.diff(series, axis=0)) > JUMP_M
        start |= valid & jump
    label = np.cumsum(start.ravel(order="F")).reshape((m, s), order="F")
    return np.where(valid, label, -1)


def _per_arc(x, label, detrend: bool, t):
    """``x`` minus its mean (or its straight-line fit) over each arc; arcs shorter than MIN_ARC -> NaN."""
    out = np.full(x.shape, np.nan)
    flat, lab = x.ravel(order="F"), label.ravel(order="F")
    tt = np.broadcast_to(t[:, None], x.shape).ravel(order="F")
    res = out.ravel(order="F")
    ok = lab >= 0
    ids, first, counts = np.unique(lab[ok], return_index=True, return_counts=True)
    idx = np.flatnonzero(ok)
    for i0, n in zip(first, counts):
        if n < MIN_ARC:
            continue
        rows = idx[i0:i0 + n]
        y = flat[rows]
        if detrend:
            tc = tt[rows] - tt[rows].mean()
            slope = np.dot(tc, y - y.mean()) / np.dot(tc, tc)
            res[rows] = y - y.mean() - slope * tc
        else:
            res[rows] = y - y.mean()
    return res.reshape(x.shape, order="F")


def pairs(signals, systems_of_signals, freq) -> dict:
    """{signal: partner signal of the same system with the most distant frequency} (the best-conditioned
    dual-frequency combination: B1C with B1I, 14 MHz apart, would amplify the carrier noise 100-fold)."""
    out = {}
    for i, a in enumerate(signals):
        best = None
        for j, b in enumerate(signals):
            if i != j and systems_of_signals[i] == systems_of_signals[j] and freq[i] != freq[j]:
                if best is None or abs(freq[i] - freq[j]) > abs(freq[i] - freq[best]):
                    best = j
        if best is not None:
            out[a] = signals[best]
    return out


def _per_satellite(signals, freq) -> dict:
    """{signal: carrier frequency Hz, a number or (S,) per satellite} from ``freq`` (G,) or (S, G) (GLONASS FDMA:
    each satellite its own; NaN where unknown)."""
    freq = np.asarray(freq, dtype=float)
    return {s: (freq[j] if freq.ndim == 1 else freq[:, j]) for j, s in enumerate(signals)}


def nominal(signals) -> np.ndarray:
    """Each signal's nominal carrier frequency (G,) Hz (channel 0 for FDMA)."""
    from ..gnss import signals as sigmod

    return np.array([sigmod.get(s).freq_hz for s in signals])


def multipath(obs, signals, freq, t) -> dict:
    """{signal: (M, S) code multipath-plus-noise series, m, zero-mean per arc} (module docstring); ``freq`` (G,) or
    per satellite (S, G) Hz."""
    fr = _per_satellite(signals, freq)
    wl = {s: C_LIGHT / f for s, f in fr.items()}
    sys_of = [_system(s) for s in signals]
    partner = pairs(signals, sys_of, nominal(signals))
    out = {}
    for s in signals:
        p, li = obs["code"][s], obs["carrier"][s] * wl[s]
        lli = obs["lli"][s].astype(np.uint8)
        if s in partner:
            b = partner[s]
            lj = obs["carrier"][b] * wl[b]
            a = (fr[s] / fr[b]) ** 2
            mp = p - (1 + 2 / (a - 1)) * li + (2 / (a - 1)) * lj
            lli = lli | obs["lli"][b].astype(np.uint8)
            detrend = False
        else:
            mp, detrend = p - li, True
        valid = np.isfinite(mp)
        out[s] = _per_arc(mp, arcs(valid, lli, t, mp), detrend, t)
    return out


def _system(signal: str) -> str:
    from ..gnss import signals as sigmod

    return sigmod.get(signal).system


def carrier_noise(obs, signals, freq, t) -> dict:
    """{"A+B": (M, S) third differences of the geometry-free phase / sqrt(20), m} for each dual-frequency pair;
    ``freq`` (G,) or per satellite (S, G) Hz."""
    wl = {s: C_LIGHT / f for s, f in _per_satellite(signals, freq).items()}
    partner = pairs(signals, [_system(s) for s in signals], nominal(signals))
    out = {}
    done = set()
    for a, b in partner.items():
        if (b, a) in done:
            continue
        done.add((a, b))
        gf = obs["carrier"][a] * wl[a] - obs["carrier"][b] * wl[b]
        lli = obs["lli"][a].astype(np.uint8) | obs["lli"][b].astype(np.uint8)
        label = arcs(np.isfinite(gf), lli, t, gf)
        d3 = np.full(gf.shape, np.nan)
        same = (label[3:] == label[:-3]) & (label[3:] >= 0)
        d3[3:] = np.where(same, gf[3:] - 3 * gf[2:-1] + 3 * gf[1:-2] - gf[:-3], np.nan)
        out[f"{a}+{b}"] = d3 / np.sqrt(20.0)
    return out


def doppler_residual(obs, signals, t) -> dict:
    """{signal: (M, S) Doppler minus the carrier-phase rate (central differences), Hz} where both exist."""
    out = {}
    for s in signals:
        d, phi = obs["doppler"][s], obs["carrier"][s]
        if not np.isfinite(d).any():
            continue
        rate = np.full(phi.shape, np.nan)
        lli = obs["lli"][s].astype(np.uint8)
        label = arcs(np.isfinite(phi), lli, t)
        same = (label[2:] == label[:-2]) & (label[2:] >= 0)
        dt = (t[2:] - t[:-2])[:, None]
        rate[1:-1] = np.where(same, (phi[2:] - phi[:-2]) / dt, np.nan)
        out[s] = d + rate   # RINEX: phase grows with the range, Doppler is positive for an approaching satellite
    return out


def slips_per_hour(obs, signals, t) -> dict:
    """{signal: loss-of-lock flags (bit 0) that are not the first epoch of a track, per tracked hour}."""
    dt = float(np.median(np.diff(t))) if t.size > 1 else 1.0
    out = {}
    for s in signals:
        on = np.isfinite(obs["carrier"][s])
        first = on & np.concatenate([np.ones((1, on.shape[1]), bool), ~on[:-1]])
        flags = ((obs["lli"][s].astype(np.uint8) & 1) != 0) & on & ~first
        hours = on.sum() * dt / 3600.0
        out[s] = float(flags.sum() / hours) if hours > 0 else None
    return out
