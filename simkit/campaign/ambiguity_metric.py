"""Single-epoch ambiguity success of one run: ILS on the double-differenced carrier and code of one antenna pair.

For every epoch with at least ``min_dd`` double differences (DDs against the highest satellite of the signal's
system, :mod:`simkit.gnss.differencing`), the float solution of :func:`simkit.gnss.differencing.float_solution`
(DD carrier in cycles and code in m, unknown DD ambiguities and ENU baseline, equal-weight undifferenced noise
with the run's median ``sigma_carrier`` / ``sigma_code``) is fixed by ILS (:func:`simkit.ambiguity.ils_batch`)
and compared with the DDs of the true integer ambiguities ``/gnss/obs/<signal>/ambiguity``. The DD geometry row
of satellite s is -(e_s - e_ref) with e the ENU unit vector towards the satellite at the master antenna
(``/gnss/truth/azimuth``, ``elevation``); the plane-wave error is b^2 / (2 range), below 1e-5 cycles for 10 m.
Model errors the float solution ignores (multipath, DD atmosphere, elevation-dependent noise) lower the success
below the bootstrapped rate ``bootstrap_sr_mean`` that the same model predicts (a lower bound of ILS success
when the model holds: Teunissen 1999).
"""
from __future__ import annotations

import numpy as np

from ..ambiguity import bootstrap_success_rate, ils_batch
from ..gnss.differencing import double_difference, float_solution, reference_satellites, systems_of
from ..gnss.signals import SIGNALS
from ..io import gnss_signals, n_antennas, read_gnss
from .registry import register

MIN_SIGMA_PHASE_M = 1e-4   # floors for files simulated with noise switched off (a singular float model otherwise)
MIN_SIGMA_CODE_M = 1e-2


def _los_enu(az: np.ndarray, el: np.ndarray) -> np.ndarray:
    """ENU unit vectors (..., 3) towards azimuth ``az`` (clockwise from north) and elevation ``el``, rad."""
    return np.stack([np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)], axis=-1)


def dd_observations(ds, signal: str, pair=(0, 1)) -> dict:
    """DD carrier (M, S) cycles, code (M, S) m, true ambiguity (M, S), geometry G (M, S, 3) and the usable mask
    (M, S) of ``signal`` between antennas ``pair`` (master first) over the satellites of the signal's system."""
    g = read_gnss(ds, signals=[signal], obs=("carrier", "code", "ambiguity"), truth=("elevation", "azimuth"),
                  satellites=False)
    sat_ids = g.sat_id
    cols = np.flatnonzero(systems_of(sat_ids) == SIGNALS[signal].system)
    ants = list(pair)

    def select(x):
        return x[:, ants][:, :, cols]

    carrier, code = select(g.obs["carrier"][signal]), select(g.obs["code"][signal])
    amb = select(g.obs["ambiguity"][signal]).astype(float)
    el, az = select(g.truth["elevation"])[:, 0], select(g.truth["azimuth"])[:, 0]
    valid = np.isfinite(carrier).all(axis=1) & np.isfinite(code).all(axis=1)
    ref = reference_satellites(el, valid, sat_ids[cols])
    e = _los_enu(az, el)
    e_ref = np.take_along_axis(e, np.clip(ref, 0, None)[:, :, None], axis=1)
    dd = {name: double_difference(x, ref)[:, 0] for name, x in (("carrier", carrier), ("code", code),
                                                                 ("ambiguity", amb))}
    dd["G"] = -(e - e_ref)
    dd["ok"] = np.isfinite(dd["carrier"]) & np.isfinite(dd["code"])
    return dd


def _sigma(ds, signal: str, name: str, floor: float) -> float:
    key = f"{signal}/{name}"
    s = read_gnss(ds, signals=[signal], truth=(key,), satellites=False).truth[key]
    s = s[np.isfinite(s)]
    return max(float(np.median(s)) if s.size else 0.0, floor)


def single_epoch_ils(dd: dict, wavelength_m: float, sigma_phase_m: float, sigma_code_m: float,
                     min_dd: int = 3) -> dict:
    """Fix every epoch of ``dd`` (from :func:`dd_observations`) with at least ``min_dd`` DDs; epochs are grouped
    by their number of DDs so each group is one batched float solution and one batched ILS call."""
    count = dd["ok"].sum(axis=1)
    successes, trials, boot = 0, 0, 0.0
    for n in np.unique(count[count >= min_dd]):
        rows = np.flatnonzero(count == n)
        order = np.argsort(~dd["ok"][rows], axis=1, kind="stable")[:, :n]   # the usable DDs first, in index order

        def take(x):
            return np.take_along_axis(x[rows], order, axis=1)

        G = np.take_along_axis(dd["G"][rows], order[:, :, None], axis=1)
        fs = float_solution(G, take(dd["carrier"])[:, None], take(dd["code"])[:, None], wavelength_m,
                            sigma_phase_m, sigma_code_m)
        res = ils_batch(fs.a_hat, fs.Qa, n_cands=1)
        truth = np.rint(take(dd["ambiguity"])).astype(np.int64)
        successes += int(np.sum(np.all(res.candidates[:, 0] == truth, axis=1) & res.finished))
        trials += rows.size
        boot += float(np.sum(bootstrap_success_rate(d=res.d)))
    return {"successes": successes, "trials": trials, "bootstrap_sum": boot,
            "skipped": int(np.sum(count < min_dd))}


@register("ambiguity")
def ambiguity(ds, signal: str | None = None, pair=(0, 1), min_dd: int = 3) -> dict:
    """Single-epoch ILS success on ``signal`` (default: the file's first) between antennas ``pair``:
    ``ils_successes``, ``ils_trials`` (epochs with at least ``min_dd`` DDs), ``bootstrap_sr_mean`` (the model's
    bootstrapped success rate averaged over those epochs), ``epochs_skipped``, ``baseline_m`` (mean length)."""
    if not gnss_signals(ds) or n_antennas(ds) < 2:
        return {}
    signal = signal or gnss_signals(ds)[0]
    g = read_gnss(ds, signals=[signal], truth=("antenna_pos_ecef",), satellites=False)
    lam = float(g.wavelength_m[0])
    r = single_epoch_ils(dd_observations(ds, signal, pair), lam, _sigma(ds, signal, "sigma_carrier",
                         MIN_SIGMA_PHASE_M), _sigma(ds, signal, "sigma_code", MIN_SIGMA_CODE_M), min_dd)
    pos = g.truth["antenna_pos_ecef"]
    return {"ils_successes": r["successes"], "ils_trials": r["trials"],
            "bootstrap_sr_mean": r["bootstrap_sum"] / r["trials"] if r["trials"] else None,
            "epochs_skipped": r["skipped"],
            "baseline_m": float(np.mean(np.linalg.norm(pos[:, pair[1]] - pos[:, pair[0]], axis=1)))}
