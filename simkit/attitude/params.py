"""Estimator parameters: documented defaults, overridden by ``--set estimator.key=value``; unknown keys fail."""
from __future__ import annotations

from ..params import merge as check
from .errors import AttitudeInputError

# The stochastic defaults are the simulator's own defaults (simkit.gnss.config: PLL 15 Hz, DLL 1 Hz, 0.5 chip,
# 20 ms; multipath 1 cm carrier / 1 m code at the horizon, e-folding elevation 20 deg), so that the float
# covariance describes the data the simulator writes.
AMBIGUITY_DEFAULTS = {
    "signals": "all",             # comma-separated signal names, or "all" of the file
    "mask_deg": 10.0,             # elevation mask (deg)
    "max_sats": 0,                # use at most this many (highest) satellites per epoch, references included; 0: all
    "validation": "pf",           # "pf" (ratio test, then only where the failure rate is proven <= pf: ILS success-
                                  # rate bound, else FFRT; C-/MC-LAMBDA fixes must equal the ILS fix), "ratio"
                                  # (fixed threshold below alone), "ffrt" (fixed failure rate pf, LAMBDA), "none"
    "ratio_threshold": 3.0,       # accept a fix when 2nd / best cost >= this (0: accept every finished search)
    "pf": 0.001,                  # pf, ffrt: tolerated failure rate per epoch, P(wrong fix accepted)
    "ffrt_samples": 10_000,       # pf, ffrt: Monte Carlo draws calibrating an epoch's threshold
    "partial_p0": 0.0,            # LAMBDA: partial fixing of rejected epochs at this bootstrapped rate; 0: off
    "max_nodes": 1_000_000,       # search work cap per epoch (nodes)
    "attitude": "wls",            # "wls" (full-covariance fit; MC-LAMBDA: its own rotation), "svd" (Wahba, weight
                                  # 1/trace per baseline), "badshah" (eq 10), "baseline" (baseline 1 heading, pitch)
    "pll_bandwidth_hz": 15.0,     # carrier thermal noise from C/N0 (Kaplan & Hegarty PLL jitter)
    "dll_bandwidth_hz": 1.0,      # code thermal noise from C/N0 (DLL jitter)
    "correlator_spacing_chips": 0.5,
    "integration_time_s": 0.02,
    "carrier_multipath_m": 0.01,  # multipath standard deviation at the horizon (m), carrier
    "code_multipath_m": 1.0,      # and code
    "multipath_elevation_deg": 20.0,  # e-folding elevation of the multipath profile (deg)
    "start_s": 0.0,               # first epoch solved (s since start)
    "stop_s": float("inf"),       # last epoch solved (s since start)
    "every": 1,                   # solve every n-th epoch only (1: all)
    "float_epochs": 1,            # float solution over the last n epochs (ambiguities constant, reset at LLI /
                                  # satellite set change); 1: single epoch
    "static": 0,                  # 1: one baseline over the float window (static site); 0: a baseline per epoch
    "continuity": 1,              # 1: keep an accepted fix until a loss-of-lock flag or gap (not with every > 1);
                                  # 0: every epoch on its own (single-epoch resolution)
}

TDCP_DEFAULTS = {
    "signals": "all",
    "mask_deg": 10.0,
    "antenna": 0,                 # which antenna's velocity (0 .. A-1)
    "carrier_sigma_m": 0.003,     # undifferenced carrier noise for the residual test (m)
    "slip_threshold": 5.0,        # reject a time difference whose residual exceeds this many sigma
    "start_s": 0.0,
    "stop_s": float("inf"),
    "every": 1,                   # difference every n-th epoch with the one before it
    "troposphere": 1,             # 1: remove the modelled troposphere change (Saastamoinen, at the code position)
    "lever_attitude": "auto",     # attitude for the IMU-centre velocity: attitude (solver), truth, none; auto:
                                  # the solver with 3+ antennas, else none
    "lever_rate": "attitude",     # turn of the lever arm from the attitude at both ends ("attitude") or the IMU gyro
}


def merge(defaults: dict, params: dict | None, solver: str) -> dict:
    """``defaults`` overridden by ``params``, each checked against :data:`simkit.params.SCHEMA` (types, ranges,
    choices); unknown keys and bad values raise :class:`AttitudeInputError` naming ``estimator.<key>``."""
    return check(defaults, params, solver, AttitudeInputError)
