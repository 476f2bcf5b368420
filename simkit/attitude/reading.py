"""From a simkit file (``simkit.io.Dataset``) to the arrays the attitude pieces take: the only file access here."""
from __future__ import annotations

from dataclasses import dataclass

import warnings

import numpy as np

from ..gnss import signals as gsig
from ..gnss.noise import dll_sigma_m, pll_sigma_m
from ..io import gnss_signals, has, path_of, read_gnss
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


# GLONASS FDMA signals are left out of the double differences and integer fixing: a DD of carriers on two
# frequencies is lambda_i N_i - lambda_j N_j, not a wavelength times an integer, and the receiver's inter-channel
# biases (which RTKLIB can estimate, glomodear) are not modelled here. "all" skips them; naming one is an error.
FDMA_EXCLUDED = ("GLONASS FDMA signals are not used for DD attitude: DD ambiguities across frequency channels "
                 "are not integers (no inter-channel bias handling)")


def _signals(ds, wanted: str) -> tuple:
    have = gnss_signals(ds)
    if wanted == "all":
        return tuple(s for s in have if s not in gsig.SIGNALS or not gsig.get(s).is_fdma)
    names = tuple(s.strip() for s in wanted.split(",") if s.strip())
    for s in names:
        if s not in have:
            raise AttitudeInputError("estimator.signals", f"{s!r} is not in the file; expected some of {have}")
        if gsig.get(s).is_fdma:
            raise AttitudeInputError("estimator.signals", f"{s!r}: {FDMA_EXCLUDED}")
    return names


def _variances(cn0, el, wavelength, chip, p):
    """Undifferenced carrier and code variances (m^2): C/N0 thermal jitter plus the elevation multipath profile;
    and the carrier multipath part alone (the time-correlated one)."""
    mp = np.exp(-el / np.radians(p["multipath_elevation_deg"]))
    vc = pll_sigma_m(cn0, wavelength, p["pll_bandwidth_hz"], p["integration_time_s"]) ** 2
    vp = dll_sigma_m(cn0, chip, p["dll_bandwidth_hz"], p["correlator_spacing_chips"], p["integration_time_s"]) ** 2
    vm = (p["carrier_multipath_m"] * mp) ** 2
    return vc + vm, vp + (p["code_multipath_m"] * mp) ** 2, vm + 0.0 * vc


NEEDED = (("gnss", "t"), ("obs", None), ("antennas", "lever_arm_b"), ("gnss", "sat_pos_ecef"))


def read(ds, p: dict) -> FileData:
    """Read the GNSS part of ``ds`` for the parameters ``p`` (signals, start_s, stop_s, noise model)."""
    for group, name in NEEDED:
        if not has(ds, group, name):
            raise AttitudeInputError(path_of(group, name),
                                     "missing from the file; expected a simkit file with GNSS observations")
    n_ant = ds[path_of("antennas", "lever_arm_b")].shape[0]
    if n_ant < 2:  # before the observations: an imported real file has one antenna and no true ambiguities
        raise AttitudeInputError(path_of("antennas", "lever_arm_b"),
                                 f"{n_ant} antenna(s); expected at least 2 (one baseline)")
    t_all = read_gnss(ds, satellites=False).t
    sel = np.flatnonzero((t_all >= p["start_s"]) & (t_all <= p["stop_s"]))
    if sel.size == 0:
        raise AttitudeInputError("estimator.start_s", f"no GNSS epoch in [{p['start_s']}, {p['stop_s']}] s")
    if p["every"] < 1:
        raise AttitudeInputError("estimator.every", f"{p['every']}; expected an integer >= 1")
    sl = slice(sel[0], sel[-1] + 1, p["every"])
    names = _signals(ds, p["signals"])
    g = read_gnss(ds, signals=names, epochs=sl, obs=("code", "carrier", "cn0", "ambiguity", "lli"))
    code = np.stack([g.obs["code"][s] for s in names])
    with warnings.catch_warnings():  # a satellite no signal tracks: its mean is NaN, as wanted
        warnings.simplefilter("ignore", RuntimeWarning)
        receiver = code_position(np.nanmean(code[:, :, 0], axis=0), g.sat_pos_ecef, g.sat_clock, g.sat_id)
    los, el = lines_of_sight(receiver, g.sat_pos_ecef)
    sigs = [gsig.get(s) for s in names]
    lam = np.array([s.wavelength_m for s in sigs])
    var = [_variances(g.obs["cn0"][n], el[:, None, :], s.wavelength_m, s.chip_length_m, p)
           for n, s in zip(names, sigs)]
    obs = Observations(np.stack([g.obs["carrier"][s] for s in names]), code,
                       np.stack([v[0] for v in var]), np.stack([v[1] for v in var]), lam, los, el,
                       g.sat_id, np.stack([v[2] for v in var]))
    amb = np.stack([g.obs["ambiguity"][s] for s in names])
    lli = np.stack([g.obs["lli"][s] for s in names])
    return FileData(g.t, obs, amb, lli, g.lever_arm_b, names, receiver, g.sat_pos_ecef, g.sat_clock)
