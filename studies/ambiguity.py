"""Single-epoch, single-frequency attitude experiment: constrained (C-LAMBDA) vs plain LAMBDA success rates.

Simulated model (documented in docs/ambiguity.md), each piece replaceable:
- geometry: ``los_sampler(rng, n_sats, trials) -> (trials, n_sats, 3)`` unit line-of-sight vectors (local ENU).
  The default draws satellites uniformly over the sky above the elevation mask (sin(elevation) uniform, azimuth
  uniform); simkit.gnss line-of-sight vectors of a real constellation can be passed instead.
- observations: double differences against the highest satellite, between a master antenna and r others,
  ``carrier = G b / lambda + a + noise`` (cycles) and ``code = G b + noise`` (m), ``G = -(e_j - e_ref)``; the noise
  is undifferenced white noise (sigma_phase, sigma_code, no elevation weighting) pushed through the differencing,
  so the DD covariance is exact. :func:`simkit.gnss.differencing.float_solution` takes any such DD observations (e.g. from simkit.gnss).
- baselines: length uniform in ``length_range_m``, heading uniform, elevation uniform in +-10 deg.
"""
from __future__ import annotations

import numpy as np

from simkit.ambiguity.constrained import baseline_constrained_ils
from simkit.ambiguity.search import ils_batch
from simkit.ambiguity.success import bootstrap_success_rate
from simkit.gnss.differencing import double_difference, float_solution, reference_satellites
from simkit.gnss.signals import SIGNALS
from simkit.rng import generator

GPS_L1_WAVELENGTH_M = SIGNALS["L1C"].wavelength_m


def sky_uniform_los(rng, n_sats, trials, mask_deg=10.0):
    """Unit vectors (trials, n_sats, 3) in ENU uniformly distributed over the sky above ``mask_deg``."""
    sin_el = rng.uniform(np.sin(np.radians(mask_deg)), 1.0, (trials, n_sats))
    az = rng.uniform(0.0, 2 * np.pi, (trials, n_sats))
    cos_el = np.sqrt(1.0 - sin_el**2)
    return np.stack([cos_el * np.sin(az), cos_el * np.cos(az), sin_el], axis=-1)


def _double_differences(x, ref_sat):
    """DDs of ``x`` (T, A, S) against antenna 0 and the satellites ``ref_sat`` (T, S), reference columns dropped:
    (T, A-1, S-1), the other satellites in index order."""
    dd = double_difference(x, ref_sat)
    keep = np.argsort(ref_sat == np.arange(x.shape[2]), axis=1, kind="stable")[:, :-1]  # (T, S-1)
    return np.take_along_axis(dd, keep[:, None, :], axis=2)


def simulate_epochs(rng, los, baselines_m, wavelength_m, sigma_phase_m, sigma_code_m):
    """DD geometry, observations and true DD ambiguities for baselines (T, 3, r) seen along ``los`` (T, S, 3).

    The differences are simkit.gnss.differencing's: antenna 0 is the master (at the origin) and each epoch's
    reference satellite is the highest one. Returns (G (T, S-1, 3), carrier (T, r, S-1) cycles, code (T, r, S-1) m,
    a_true (T, r, S-1) int64).
    """
    T, S, _ = los.shape
    r = baselines_m.shape[2]
    sat_ids = [f"G{s + 1:02d}" for s in range(S)]  # one system: one reference satellite per epoch
    ref = reference_satellites(np.arcsin(np.clip(los[:, :, 2], -1.0, 1.0)), np.ones((T, S), bool), sat_ids)
    # DD range = G b with G = -(e_s - e_ref): the DDs of "antennas" whose ranges are -e (one per ENU axis)
    unit = np.concatenate([np.zeros((T, 1, S)), -np.swapaxes(los, 1, 2)], axis=1)  # (T, 4, S)
    G = np.swapaxes(_double_differences(unit, ref), 1, 2)  # (T, S-1, 3)
    rho = np.einsum("tsi,tir->trs", G, baselines_m)  # DD ranges (T, r, S-1)

    def dd_noise(sigma):  # undifferenced noise at the r + 1 antennas
        return _double_differences(sigma * rng.standard_normal((T, r + 1, S)), ref)

    a_true = rng.integers(-50, 51, (T, r, S - 1))
    carrier = rho / wavelength_m + a_true + dd_noise(sigma_phase_m) / wavelength_m
    code = rho + dd_noise(sigma_code_m)
    return G, carrier, code, a_true


def random_baselines(rng, trials, length_range_m=(1.0, 2.0)):
    """(trials, 3, 1) ENU baselines: length uniform in the range, heading uniform, elevation uniform in +-10 deg."""
    length = rng.uniform(*length_range_m, trials)
    hdg = rng.uniform(0.0, 2 * np.pi, trials)
    el = np.radians(rng.uniform(-10.0, 10.0, trials))
    b = length[:, None] * np.stack([np.cos(el) * np.sin(hdg), np.cos(el) * np.cos(hdg), np.sin(el)], axis=1)
    return b[:, :, None]


def success_table(n_sats=range(4, 11), trials=1000, seed=0, sigma_phase_m=0.003, sigma_code_m=0.30,
                  wavelength_m=GPS_L1_WAVELENGTH_M, length_range_m=(1.0, 2.0), los_sampler=sky_uniform_los):
    """Empirical single-epoch success rates of plain ILS and C-LAMBDA for each number of satellites.

    Returns a list of dicts: ``n_sats``, ``trials``, ``ils`` and ``constrained`` (success fractions),
    ``bootstrap`` (mean exact IB success rate of the float Qa), ``unfinished`` (constrained searches that hit the
    work cap, counted as failures). Deterministic for a given ``seed`` (named streams per row).
    """
    rows = []
    for s in n_sats:
        rng = generator(seed, "ambiguity", "success_table", str(s))
        los = los_sampler(rng, s, trials)
        b = random_baselines(rng, trials, length_range_m)
        G, carrier, code, a_true = simulate_epochs(rng, los, b, wavelength_m, sigma_phase_m, sigma_code_m)
        fs = float_solution(G, carrier, code, wavelength_m, sigma_phase_m, sigma_code_m)
        truth = a_true[:, 0, :]
        plain = ils_batch(fs.a_hat, fs.Qa, n_cands=1)
        con = baseline_constrained_ils(fs.a_hat, fs.Qa, fs.b_hat, fs.Qb, fs.Qba, np.linalg.norm(b[:, :, 0], axis=1),
                                       n_cands=1)
        boot = bootstrap_success_rate(d=plain.d)
        rows.append({
            "n_sats": int(s), "trials": int(trials),
            "ils": float(np.mean(np.all(plain.candidates[:, 0] == truth, axis=1))),
            "constrained": float(np.mean(np.all(con.candidates[:, 0] == truth, axis=1) & con.finished)),
            "bootstrap": float(np.mean(boot)),
            "unfinished": int(np.sum(~con.finished)),
        })
    return rows


def format_table(rows) -> str:
    """The rows of :func:`success_table` as a Markdown table."""
    lines = ["| satellites | trials | LAMBDA (ILS) | C-LAMBDA | bootstrapped SR (mean) |", "|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['n_sats']} | {r['trials']} | {r['ils']:.3f} | {r['constrained']:.3f} | "
                     f"{r['bootstrap']:.3f} |")
    return "\n".join(lines)
