"""From a simkit file (``simkit.io.Dataset``) to the arrays the attitude pieces take: the only file access here."""
from __future__ import annotations

from dataclasses import dataclass

import warnings

import numpy as np

from ..gnss import signals as gsig
from ..gnss.noise import dll_sigma_m, pll_sigma_m
from .dd import Observations
from .errors import AttitudeInputError
from .geometry import code_position, lines_of_sight


@dataclass(frozen=True)
class FileData:
    """One file's GNSS data, epochs between start_s and stop_s: ``t`` (M,) s, ``obs`` the observations,
    ``ambiguity`` (G, M, A, S) the true integer ambiguities (for labelling fixes only), ``lli`` (G, M, A, S),
    ``lever_arm`` (A, 3) m body, ``signals`` (G,), ``receiver`` (M, 3) m ECEF code position, ``sat_pos`` (M, S, 3),
    ``sat_clock`` (M, S) s."""

    t: np.ndarray
    obs: Observations
    ambiguity: np.ndarray
    lli: np.ndarray
    lever_arm: np.ndarray
    signals: tuple
    receiver: np.ndarray
    sat_pos: np.ndarray
    sat_clock: np.ndarray


def _signals(ds, wanted: str) -> tuple:
    have = tuple(str(s) for s in ds["gnss/signals"][:])
    if wanted == "all":
        return have
    names = tuple(s.strip() for s in wanted.split(",") if s.strip())
    for s in names:
        if s not in have:
            raise AttitudeInputError("estimator.signals", f"{s!r} is not in the file; expected some of {have}")
    return names


def _variances(cn0, el, wavelength, chip, p):
    """Undifferenced carrier and code variances (m^2): C/N0 thermal jitter plus the elevation multipath profile;
    and the carrier multipath part alone (the time-correlated one)."""
    mp = np.exp(-el / np.radians(p["multipath_elevation_deg"]))
    vc = pll_sigma_m(cn0, wavelength, p["pll_bandwidth_hz"], p["integration_time_s"]) ** 2
    vp = dll_sigma_m(cn0, chip, p["dll_bandwidth_hz"], p["correlator_spacing_chips"], p["integration_time_s"]) ** 2
    vm = (p["carrier_multipath_m"] * mp) ** 2
    return vc + vm, vp + (p["code_multipath_m"] * mp) ** 2, vm + 0.0 * vc


def read(ds, p: dict) -> FileData:
    """Read the GNSS part of ``ds`` for the parameters ``p`` (signals, start_s, stop_s, noise model)."""
    for key in ("gnss/t", "gnss/obs", "gnss/antennas/lever_arm_b", "gnss/sat_pos_ecef"):
        if key not in ds:
            raise AttitudeInputError(key, "missing from the file; expected a simkit file with GNSS observations")
    t_all = ds["gnss/t"][:]
    sel = np.flatnonzero((t_all >= p["start_s"]) & (t_all <= p["stop_s"]))
    if sel.size == 0:
        raise AttitudeInputError("estimator.start_s", f"no GNSS epoch in [{p['start_s']}, {p['stop_s']}] s")
    if p["every"] < 1:
        raise AttitudeInputError("estimator.every", f"{p['every']}; expected an integer >= 1")
    sl = slice(sel[0], sel[-1] + 1, p["every"])
    names = _signals(ds, p["signals"])
    sat_pos, sat_clock = ds["gnss/sat_pos_ecef"][sl], ds["gnss/sat_clock"][sl]
    code = np.stack([ds[f"gnss/obs/{g}/code"][sl] for g in names])
    with warnings.catch_warnings():  # a satellite no signal tracks: its mean is NaN, as wanted
        warnings.simplefilter("ignore", RuntimeWarning)
        receiver = code_position(np.nanmean(code[:, :, 0], axis=0), sat_pos, sat_clock)
    los, el = lines_of_sight(receiver, sat_pos)
    sigs = [gsig.get(g) for g in names]
    lam = np.array([s.wavelength_m for s in sigs])
    var = [_variances(ds[f"gnss/obs/{g}/cn0"][sl], el[:, None, :], s.wavelength_m, s.chip_length_m, p)
           for g, s in zip(names, sigs)]
    obs = Observations(np.stack([ds[f"gnss/obs/{g}/carrier"][sl] for g in names]), code,
                       np.stack([v[0] for v in var]), np.stack([v[1] for v in var]), lam, los, el,
                       ds["gnss/sat_id"][:], np.stack([v[2] for v in var]))
    amb = np.stack([ds[f"gnss/obs/{g}/ambiguity"][sl] for g in names])
    lli = np.stack([ds[f"gnss/obs/{g}/lli"][sl] for g in names])
    return FileData(t_all[sl], obs, amb, lli, ds["gnss/antennas/lever_arm_b"][:], names, receiver, sat_pos,
                    sat_clock)
