"""``simkit twin``: simulate the receiver of a real RINEX file and measure how far the simulation is from it.

The twin is a simkit scenario built from the real file: a static antenna at the reference position (header
APPROX POSITION or the given one) or a moving one along a logged path (``trajectory``: e.g. the file's own SPP
solution), the same first epoch, span and interval, the same signals, the broadcast sky of the same navigation
files, and the elevation mask inferred from the data (the lowest elevation tracked, floored to a whole degree).
Its [gnss] error parameters are simkit's defaults, or with ``fit`` the ones estimated from the real file
(:func:`fit_parameters`, :func:`fit_horizon`, :func:`code_tables`, :mod:`.ionosphere`): the calibrated twin,
checked in sample and out of sample (fitted on the first half of the epochs, compared on the second).

Both files go through the same statistics (:mod:`.fidelity`); the comparison is returned as a JSON-ready dict.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .. import frames, gpstime
from ..constellation.geometry import angles_from_enu, lines_of_sight_enu
from ..earth import C_LIGHT
from ..errors import InputError
from ..gnss import noise as noise_model
from ..gnss import signals as sigmod
from ..gnss.config import angle_table_at
from . import acquisition, fidelity, horizon, importer, ionosphere, noise_fit, shadowing_fit, sisre

KINDS = ("code", "carrier", "doppler", "cn0", "lli")
# simkit's [gnss] defaults that the fit changes (docs/gnss.md)
DEFAULTS = {"cn0_zenith_dbhz": 45.0, "rolloff_db": 10.0, "dll_bandwidth_hz": 1.0, "pll_bandwidth_hz": 15.0,
            "fll_bandwidth_hz": 2.0, "correlator_spacing_chips": 0.5, "integration_time_s": 0.02,
            "mp_code_sigma_m": 1.0, "mp_carrier_sigma_m": 0.01, "mp_elevation_scale_deg": 20.0,
            "mp_correlation_time_s": 30.0,
            "slip_rate_per_h": 0.0}


def real_arrays(imported: importer.Imported) -> dict:
    """{t, sat_id, signals, freq (G,) Hz, sat_freq (S, G) Hz, obs {kind: {signal: (M, S)}}, sat_pos, reference}
    of an imported file."""
    d = imported.datasets
    signals = [str(s) for s in d["gnss/signals"]]
    return {"t": d["gnss/t"], "sat_id": [str(s) for s in d["gnss/sat_id"]], "signals": signals,
            "freq": d["gnss/frequency_hz"], "sat_freq": d.get("gnss/sat_frequency_hz", d["gnss/frequency_hz"]),
            "sat_pos": d["gnss/sat_pos_ecef"],
            "obs": {k: {s: d[f"gnss/obs/{s}/{k}"][:, 0] for s in signals} for k in KINDS},
            "reference": d.get("reference/pos_ecef"), "start": (int(imported.attrs["start_gps_week"]),
                                                                 float(imported.attrs["start_gps_sow"])),
            "group_delay": d.get("gnss/group_delay"), "sat_clock": d.get("gnss/sat_clock"),
            "iono": {str(k): (a, b) for k, a, b in zip(d.get("gnss/iono_systems", []), d.get("gnss/iono_alpha", []),
                                                          d.get("gnss/iono_beta", []))}}


def file_arrays(path) -> dict:
    """The same dict as :func:`real_arrays` for a simkit file (antenna 0)."""
    from ..io import open_dataset, read_gnss

    with open_dataset(path) as ds:
        g = read_gnss(ds, antennas=0, obs=KINDS)
        return {"t": g.t, "sat_id": [str(s) for s in g.sat_id], "signals": list(g.signals),
                "freq": C_LIGHT / g.wavelength_m, "sat_freq": C_LIGHT / g.sat_wavelength_m, "sat_pos": g.sat_pos_ecef,
                "obs": g.obs, "reference": None,
                "sat_clock": g.sat_clock, "group_delay": g.group_delay,
                "start": (int(ds.attrs["start_gps_week"]), float(ds.attrs["start_gps_sow"]))}


def inferred_mask_deg(real: dict, reference) -> float:
    """The lowest elevation (deg) at which the receiver tracked a satellite, floored to a whole degree (>= 0)."""
    el = np.degrees(fidelity.elevations(real["sat_pos"], reference))
    on = fidelity.tracked(real["obs"]) & np.isfinite(el)
    if not on.any():
        raise InputError("twin", "no tracked satellite has a broadcast orbit: cannot infer the elevation mask")
    return float(max(0.0, np.floor(np.min(el[on]))))


def scenario(real: dict, reference, nav_paths, mask_deg: float, params: dict, seed: int) -> dict:
    """The twin's scenario (a dict for :func:`simkit.run`)."""
    week, sow = real["start"]
    t = real["t"]
    interval = float(np.median(np.diff(t))) if t.size > 1 else 1.0
    duration = float(np.floor(t[-1] / interval + 1e-6) * interval)   # on the twin's epoch grid
    start = gpstime.gps_to_utc(week, sow)
    lla = frames.ecef_to_lla(np.asarray(reference, float)[None])[0]
    p = {**DEFAULTS, **params}
    if real.get("trajectory"):           # a moving receiver: the path of a log ([trajectory] source)
        trajectory = {"rate_hz": 1.0 / interval, **real["trajectory"]}
    else:
        trajectory = {"rate_hz": 1.0 / interval,
                      "origin": {"lat_deg": float(np.degrees(lla[0])), "lon_deg": float(np.degrees(lla[1])),
                                 "height_m": float(lla[2])},
                      "initial": {"speed_m_per_s": 0.0, "heading_deg": 0.0},
                      "segment": [{"kind": "static", "duration_s": duration}]}
    return {
        "scenario": {"name": "twin", "start": start.isoformat(timespec="microseconds").replace("+00:00", "Z"),
                     "duration_s": duration, "seed": int(seed)},
        "trajectory": trajectory,
        "gnss": {"rate_hz": 1.0 / interval, "elevation_mask_deg": mask_deg, "signals": list(real["signals"]),
                 "cn0_zenith_dbhz": p["cn0_zenith_dbhz"], "slip_rate_per_h": p["slip_rate_per_h"],
                 "constellation": [{"source": str(Path(n).resolve())} for n in nav_paths],
                 "antenna": [{"lever_arm_m": [0.0, 0.0, 0.0],
                              **({"gain_pattern": _table_entry(p["gain_pattern"], "off_boresight_deg", "gain_db")}
                                 if p.get("gain_pattern") else {"rolloff_db": p["rolloff_db"]})}],
                 "noise": {"dll_bandwidth_hz": p["dll_bandwidth_hz"], "pll_bandwidth_hz": p["pll_bandwidth_hz"],
                           "fll_bandwidth_hz": p["fll_bandwidth_hz"]},
                 "cn0_offset_db": cn0_offset_entries(p),
                 **({"satellite_cn0_offset_db": {k: dict(v) for k, v in p["satellite_cn0_offset_db"].items()}}
                    if p.get("satellite_cn0_offset_db") else {}),
                 "code_error_scale": {k: _table_entry(v, "elevation_deg", "factor")
                                      for k, v in p.get("code_error_scale", {}).items()},
                 "multipath": {"code_sigma_m": p["mp_code_sigma_m"], "carrier_sigma_m": p["mp_carrier_sigma_m"],
                               "elevation_scale_deg": p["mp_elevation_scale_deg"],
                               "correlation_time_s": p["mp_correlation_time_s"],
                               "signal_correlation_time_s": dict(p.get("mp_signal_correlation_time_s", {}))},
                 **({"truth_errors": {**({"iono_residual_fraction": p["iono_residual_fraction"]}
                                         if p.get("iono_residual_fraction") is not None else {}),
                                      **p.get("truth_errors", {})}}
                    if p.get("iono_residual_fraction") is not None or p.get("truth_errors") else {}),
                 **({"acquisition": dict(p["acquisition"])} if p.get("acquisition") else {}),
                 **({"shadowing": dict(p["shadowing"])} if p.get("shadowing") else {}),
                 **({"cn0_report": dict(p["cn0_report"])} if p.get("cn0_report") else {})},
        **({"environment": {"reflections": False, "body_mask": [dict(p["horizon_mask"])]}}
           if p.get("horizon_mask") else {}),
    }


def statistics(arr: dict, el: np.ndarray) -> dict:
    """The per-file statistics of :mod:`.fidelity` over elevation bins (``el`` (M, S) rad for its columns)."""
    obs, signals, freq, t = arr["obs"], arr["signals"], np.asarray(arr["sat_freq"]), arr["t"]
    on = fidelity.tracked(obs)
    mp = fidelity.multipath(obs, signals, freq, t)
    cn = fidelity.carrier_noise(obs, signals, freq, t)
    dop = fidelity.doppler_residual(obs, signals, t)
    return {
        "tracked_per_epoch": {"mean": float(on.sum(1).mean()), "min": int(on.sum(1).min()),
                              "max": int(on.sum(1).max())},
        "cn0_dbhz": {s: fidelity.by_elevation(obs["cn0"][s], el) for s in signals},
        "code_noise_m": {s: fidelity.by_elevation(mp[s], el, stat="std") for s in signals},
        "code_noise_robust_m": {s: fidelity.by_elevation(mp[s], el, stat="robust_std") for s in signals},
        "carrier_noise_m": {k: fidelity.robust_std(v) for k, v in cn.items()},
        "doppler_noise_hz": {k: fidelity.robust_std(v) for k, v in dop.items()},
        "slips_per_hour": fidelity.slips_per_hour(obs, signals, t),
        "_series": {"mp": mp, "cn": cn, "dop": dop},
    }


def _align(real: dict, twin: dict):
    """Twin column of each real satellite, real row of each twin epoch (-1 where absent)."""
    col = {s: i for i, s in enumerate(twin["sat_id"])}
    real_cols = np.array([col.get(s, -1) for s in real["sat_id"]])
    dt = float(np.median(np.diff(twin["t"]))) if twin["t"].size > 1 else 1.0
    tol = 0.25 * dt   # receivers that tag epochs off the grid (42.3999998 s) still pair with the grid epoch
    rows = np.clip(np.searchsorted(real["t"], twin["t"]), 1, max(real["t"].size - 1, 1))
    rows = np.where(np.abs(real["t"][rows - 1] - twin["t"]) < np.abs(real["t"][rows] - twin["t"]), rows - 1, rows)
    rows = np.where(np.abs(real["t"][rows] - twin["t"]) < tol, rows, -1)
    return real_cols, rows


def on_twin_grid(real: dict, twin: dict) -> dict:
    """The real arrays re-indexed onto the twin's epochs and satellites (NaN / 0 where the real file has none)."""
    cols, rows = _align(real, twin)
    m, s = twin["t"].size, len(twin["sat_id"])
    keep_c = cols >= 0
    keep_r = rows >= 0
    obs = {}
    for kind in KINDS:
        obs[kind] = {}
        for sig in real["signals"]:
            fill = 0 if kind == "lli" else np.nan
            a = np.full((m, s), fill, dtype=np.uint8 if kind == "lli" else float)
            src = real["obs"][kind][sig][rows[keep_r]][:, keep_c]
            a[np.ix_(np.flatnonzero(keep_r), cols[keep_c])] = src
            obs[kind][sig] = a
    real_freq = np.broadcast_to(np.asarray(real["sat_freq"], float), (len(real["sat_id"]), len(real["signals"])))
    sat_freq = np.full((s, len(real["signals"])), np.nan)
    sat_freq[cols[keep_c]] = real_freq[keep_c]
    return {**real, "t": twin["t"], "sat_id": twin["sat_id"], "obs": obs, "sat_pos": twin["sat_pos"],
            "sat_clock": twin.get("sat_clock"), "sat_freq": sat_freq,
            "not_in_twin": [real["sat_id"][i] for i in np.flatnonzero(~keep_c)]}


def compare(real: dict, twin: dict, reference, mask_deg: float) -> dict:
    """Real (on the twin's grid) against twin: tracking, C/N0, code noise, carrier and Doppler noise, slips."""
    el = fidelity.elevations(twin["sat_pos"], reference)
    rs, ts = statistics(real, el), statistics(twin, el)
    above = np.degrees(el) >= mask_deg
    r_on, t_on = fidelity.tracked(real["obs"]), fidelity.tracked(twin["obs"])
    agree = float(np.mean(r_on[above] == t_on[above])) if above.any() else None
    out = {"elevation_bins_deg": fidelity.ELEVATION_EDGES_DEG.tolist(), "mask_deg": mask_deg,
           "visibility_agreement": agree,
           "satellite_epochs_above_mask": int(above.sum()),
           "tracked_real_not_twin": int((r_on & ~t_on & above).sum()),
           "tracked_twin_not_real": int((t_on & ~r_on & above).sum()),
           "tracked_below_mask_real": int((r_on & ~above).sum()),
           "disagreement_max_elevation_deg": float(np.degrees(el[above & (r_on != t_on)]).max())
           if (above & (r_on != t_on)).any() else None,
           "tracked_series": {"t": twin["t"].tolist(), "real": r_on.sum(1).tolist(), "twin": t_on.sum(1).tolist()},
           "real": {k: v for k, v in rs.items() if k != "_series"},
           "twin": {k: v for k, v in ts.items() if k != "_series"},
           "satellites_without_orbit": real.get("not_in_twin", [])}
    # C/N0 over the satellite-epochs both track: a satellite only the twin sees (a building the twin does not
    # model) has no real C/N0 to compare with
    both = {s: np.isfinite(real["obs"]["cn0"][s]) & np.isfinite(twin["obs"]["cn0"][s]) for s in real["signals"]}
    common = {s: (fidelity.by_elevation(np.where(both[s], real["obs"]["cn0"][s], np.nan), el),
                  fidelity.by_elevation(np.where(both[s], twin["obs"]["cn0"][s], np.nan), el)) for s in real["signals"]}
    out["cn0_dbhz_common"] = {s: {"real": r, "twin": t} for s, (r, t) in common.items()}
    out["cn0_rms_difference_dbhz"] = {s: _rms_diff(*common[s]) for s in real["signals"]}
    out["code_noise_ratio"] = {s: _ratios(ts["code_noise_m"][s], rs["code_noise_m"][s]) for s in real["signals"]}
    return out


def _rms_diff(a, b):
    d = [x - y for x, y in zip(a, b) if x is not None and y is not None]
    return float(np.sqrt(np.mean(np.square(d)))) if d else None


def _ratios(twin, real):
    return [None if x is None or y is None or y == 0 else float(x / y) for x, y in zip(twin, real)]


def fit_parameters(real: dict, reference) -> dict:
    """simkit [gnss] error parameters estimated from the real file (the calibrated twin's).

    * C/N0: least squares of C/N0 = cn0_zenith + signal offset - rolloff ((90 - el) / 90)^2 (the simulator's
      model, :mod:`simkit.gnss.noise`) over every observation with a signal strength, then the gain pattern per
      elevation bin (:func:`_gain_pattern`); defaults when none.
    * Code: the code-minus-carrier scatter per signal and elevation bin against the simulator's code error
      f_s sqrt(DLL jitter(C/N0(el))^2 + (sigma_h exp(-el / el0))^2): one multipath profile (sigma_h, el0) and a
      per-signal factor f_s (``[gnss.code_error_scale]``: a receiver's correlators and multipath mitigation differ
      by code), in log least squares (:func:`_fit_code`); the multipath correlation time from the lag-one
      autocorrelation of the multipath series.
    * Carrier and Doppler (:func:`rescale`, after a first twin): the carrier error terms (PLL jitter, carrier
      multipath) and the FLL jitter scaled by the ratio of the real to the twin's measured carrier noise
      (geometry-free third differences) and Doppler noise: both terms are linear in these scales.
    * Slips: loss-of-lock flags per tracked hour.
    """
    el = fidelity.elevations(real["sat_pos"], reference)
    st = statistics(real, el)
    p = dict(DEFAULTS)
    notes = []
    sigs = [sigmod.get(s) for s in real["signals"]]
    if not _fit_cn0(real, sigs, el, p):
        notes.append("no signal-strength observations: C/N0 model left at the defaults")
    edges = fidelity.ELEVATION_EDGES_DEG
    centres = np.radians(0.5 * (edges[:-1] + edges[1:]))
    dt = float(np.median(np.diff(real["t"]))) if real["t"].size > 1 else 1.0

    def cn0_at(g, e):
        return noise_model.cn0_dbhz(np.pi / 2 - e, p["cn0_zenith_dbhz"], p["rolloff_db"], _cn0_offset(g, p))

    code = _fit_code(st, sigs, centres, lambda g, c: noise_model.dll_sigma_m(
        cn0_at(g, c), g.chip_length_m, p["dll_bandwidth_hz"], p["correlator_spacing_chips"], p["integration_time_s"]))
    if code is None:
        notes.append("too few code-minus-carrier bins: code noise and multipath left at the defaults")
    else:
        p["mp_code_sigma_m"], p["mp_elevation_scale_deg"], p["code_error_scale"] = code
    # a correlation time per signal from its lag-one autocorrelation (a non-positive one: shorter than the interval,
    # the floor dt / 5), the median over signals for the others: one signal's series would rule a pooled estimate
    rhos = {s: noise_fit.lag_one(v) for s, v in st["_series"]["mp"].items()}
    taus = {s: float(np.clip(-dt / np.log(r), dt / 5.0, 3600.0)) if r > 0.0 else dt / 5.0
            for s, r in rhos.items() if r is not None and r < 1.0}
    if taus:
        p["mp_correlation_time_s"] = float(np.median(list(taus.values())))
        p["mp_signal_correlation_time_s"] = taus
    rates = [v for v in st["slips_per_hour"].values() if v is not None]
    p["slip_rate_per_h"] = float(np.mean(rates)) if rates else 0.0
    if real.get("group_delay") is not None and real.get("iono"):
        iono = ionosphere.klobuchar_ratio(real, reference, real["group_delay"], real["iono"])
        p["_ionosphere"] = iono
        p["iono_residual_fraction"] = ionosphere.residual_fraction(iono)
    if real.get("sat_clock") is not None and not real.get("trajectory"):   # a static station with a known position
        p["_sisre"] = sisre.fit(sisre.residuals(real, reference))
        p["truth_errors"], more = sisre.parameters(p["_sisre"], float(real["t"][-1] - real["t"][0]))
        notes += more
    if p.get("iono_residual_fraction") is None:
        notes.append("no dual-frequency GPS or BDS code and carrier with a Klobuchar model: the truth "
                     "ionosphere's residual left at the default")
    p["_notes"] = notes
    return p


def _fit_cn0(real, sigs, el, p) -> bool:
    """Set ``p``'s C/N0 model from the real C/N0 (:func:`_fit_cn0_levels`) and the step of its reported values
    ([gnss.cn0_report]); at a fixed antenna also each satellite's own offset (:func:`_satellite_offsets`), the
    levels fitted again on the C/N0 less those offsets (three rounds: a bin's mean is partly which satellites
    are in it). False when the file has no signal strength."""
    step = noise_fit.cn0_resolution(real["obs"]["cn0"].values())
    if step > 0:   # the receiver writes its C/N0 in steps: the twin's is rounded the same way
        p["cn0_report"] = {"resolution_dbhz": step}
    cn0 = real["obs"]["cn0"]
    static = not real.get("trajectory")    # at a street the levels are the street's (the shadowing fit's)
    if not _fit_cn0_levels(cn0, sigs, el, p, static):
        return False
    if static:
        for _ in range(3):
            offsets = _satellite_offsets(cn0, sigs, el, p, real["sat_id"])
            if not offsets:
                break
            rows = {s: np.array([v.get(k, 0.0) for k in real["sat_id"]]) for s, v in offsets.items()}
            _fit_cn0_levels({s: c - rows.get(s, 0.0) for s, c in cn0.items()}, sigs, el, p, static)
        if offsets:
            p["satellite_cn0_offset_db"] = offsets
    return True


def _fit_cn0_levels(cn0: dict, sigs, el, p, static: bool) -> bool:
    """Zenith C/N0, rolloff and per-signal offsets (least squares of the quadratic model with one offset per
    signal beyond the first, relative to the signal table's), then the gain pattern (:func:`_gain_pattern`) and,
    at a fixed antenna, the per-signal tables (:func:`_signal_patterns`), from C/N0 ``cn0`` (signal -> (M, S))."""
    rows_x, rows_y, names = [], [], []
    for g in sigs:
        c = cn0[g.name]
        ok = np.isfinite(c) & np.isfinite(el)
        if ok.any():
            x = ((np.pi / 2 - el[ok]) / (np.pi / 2)) ** 2
            rows_x.append((np.ones(x.size), -x))
            rows_y.append(c[ok] - g.cn0_offset_db)
            names.append(g.name)
    if not rows_x:
        return False
    a = np.zeros((sum(r[0].size for r in rows_x), 1 + len(names)))
    at = 0
    for k, (one, x) in enumerate(rows_x):
        a[at:at + one.size, 0], a[at:at + one.size, 1] = one, x
        if k:
            a[at:at + one.size, 1 + k] = 1.0
        at += one.size
    sol = np.linalg.lstsq(a, np.concatenate(rows_y), rcond=None)[0]
    p["cn0_zenith_dbhz"] = float(np.clip(sol[0], 10.0, 70.0))
    p["rolloff_db"] = float(max(sol[1], 0.0))
    p["cn0_offset_db"] = {n: float(np.clip(v, -30.0, 30.0)) for n, v in zip(names[1:], sol[2:])}
    p.pop("cn0_offset_table", None)
    p["gain_pattern"] = _gain_pattern(cn0, sigs, el, p)
    if static:
        _signal_patterns(cn0, [g for g in sigs if g.name in names], el, p)
    return True


def _model_cn0(g, el, p):
    """The fitted C/N0 (dB-Hz) of signal ``g`` at elevations ``el`` (rad) of a level antenna: zenith, the
    signal's offset (its table where it has one), the gain pattern."""
    theta = np.pi / 2 - el
    offset = angle_table_at(p.get("cn0_offset_table", {}).get(g.name, p["cn0_offset_db"].get(g.name, 0.0)), theta)
    return (p["cn0_zenith_dbhz"] + g.cn0_offset_db + offset
            + np.interp(np.degrees(theta), p["gain_pattern"][0], p["gain_pattern"][1]))


# satellites' C/N0 differ beyond their sampling when the chi-square of their mean residuals has a p-value under this
SATELLITE_OFFSET_P = 1e-3


def _satellite_offsets(cn0: dict, sigs, el, p, sat_ids) -> dict:
    """Per signal, each satellite's mean C/N0 residual to the model (:func:`_model_cn0`), less their mean
    weighted by epochs (the model keeps the level): {signal: {satellite: dB}}, for the signals whose satellites
    differ beyond sampling (the chi-square of the means in their standard errors, n_eff from each series'
    lag-one autocorrelation, has a p-value under :data:`SATELLITE_OFFSET_P`). A satellite with fewer than 10
    values gets none."""
    from scipy.stats import chi2

    out = {}
    for g in sigs:
        r = cn0[g.name] - _model_cn0(g, el, p)
        n = np.isfinite(r).sum(axis=0)
        keep = np.flatnonzero(n >= 10)
        if keep.size < 2:
            continue
        means = np.array([np.nanmean(r[:, k]) for k in keep])
        ses = []
        for k, m in zip(keep, means):
            v = r[:, k][np.isfinite(r[:, k])]
            ne = noise_fit.n_effective(v.size, noise_fit.lag_one(r[:, k] - m))
            ses.append(max(float(np.std(v)), 0.05) / np.sqrt(ne))
        centred = means - np.average(means, weights=n[keep])
        stat = float(np.sum((centred / np.array(ses)) ** 2))
        if chi2.sf(stat, keep.size - 1) < SATELLITE_OFFSET_P:
            out[g.name] = {sat_ids[k]: float(np.clip(v, -30.0, 30.0)) for k, v in zip(keep, centred)}
    return out


# a signal's C/N0 levels per bin differ from the shared pattern beyond sampling when the chi-square of the
# differences in their standard errors has a p-value under this
SIGNAL_PATTERN_P = 1e-3


def _signal_patterns(cn0: dict, sigs, el, p) -> None:
    """Per-signal C/N0 offset tables of a fixed antenna, where one gain pattern does not serve every signal.

    Each signal's mean C/N0 (less its offset) per 10-degree bin is compared with the shared pattern's level there,
    in the bins' standard errors (:func:`noise_fit.bin_mean`: the jackknife over satellites counts their power
    differences). When a signal's chi-square has a p-value under :data:`SIGNAL_PATTERN_P` (GPS L2 P(Y) tracked
    semi-codelessly falls faster with elevation than L1 C/A), the gain pattern becomes the first signal's own
    and every other signal gets ``p["cn0_offset_table"][name]``: its level minus the first signal's, per bin,
    fitted by weighted least squares as a + b (theta / 90 deg)^2 (theta the angle from boresight: a rolloff of
    its own), tabulated every 10 degrees. Two numbers per signal, not one per bin: a bin's mean is mostly which
    satellites are in it."""
    from scipy.stats import chi2

    edges = fidelity.ELEVATION_EDGES_DEG
    el_deg = np.degrees(el)
    shared = p["cn0_zenith_dbhz"] + np.array(p["gain_pattern"][1][::2])[::-1]     # level per bin, lowest first
    bins, significant = {}, False
    for g in sigs:
        x = cn0[g.name] - _cn0_offset(g, p)
        bins[g.name] = [b if b["n"] >= 10 and b["mean"] is not None and b["se"] else None
                        for b in (noise_fit.bin_mean(x, el_deg, lo, hi) for lo, hi in zip(edges[:-1], edges[1:]))]
        z = [(b["mean"] - lv) / b["se"] for b, lv in zip(bins[g.name], shared) if b is not None]
        significant |= len(z) > 1 and chi2.sf(float(np.sum(np.square(z))), len(z)) < SIGNAL_PATTERN_P
    if not significant or len(sigs) < 2:
        return
    first = bins[sigs[0].name]
    p["gain_pattern"] = _pattern([b["mean"] if b is not None else None for b in first], p)
    theta = 90.0 - 0.5 * (edges[:-1] + edges[1:])          # each bin's centre, from boresight (deg)
    nodes = np.arange(0.0, 91.0, 10.0)
    tables = {}
    for g in sigs[1:]:
        rows = [(t, a["mean"] - b["mean"], np.hypot(a["se"], b["se"]))
                for t, a, b in zip(theta, bins[g.name], first) if a is not None and b is not None]
        if len(rows) < 2:
            continue
        t, d, se = (np.array(c) for c in zip(*rows))
        design = np.column_stack([np.ones(t.size), (t / 90.0) ** 2]) / se[:, None]
        coef = np.linalg.lstsq(design, d / se, rcond=None)[0]
        level = p["cn0_offset_db"].get(g.name, 0.0) + coef[0] + coef[1] * (nodes / 90.0) ** 2
        tables[g.name] = (tuple(float(n) for n in nodes), tuple(float(v) for v in np.clip(level, -30.0, 30.0)))
    p["cn0_offset_table"] = tables


def cn0_offset_entries(p: dict) -> dict:
    """The scenario's [gnss.cn0_offset_db] of fitted parameters ``p``: a signal's table where it has one, else
    its offset (dB)."""
    tables = p.get("cn0_offset_table", {})
    out = {k: v for k, v in p.get("cn0_offset_db", {}).items() if k not in tables}
    out.update({k: _table_entry(v, "off_boresight_deg", "offset_db") for k, v in tables.items()})
    return out


def _cn0_offset(g, p) -> float:
    """Signal ``g``'s C/N0 offset (dB): the signal table's plus the fitted one of ``p``."""
    return g.cn0_offset_db + p.get("cn0_offset_db", {}).get(g.name, 0.0)


def _gain_pattern(cn0: dict, sigs, el, p) -> tuple:
    """The antenna gain pattern (off-boresight deg, gain dB) of a level antenna (off-boresight = 90 deg -
    elevation), a step per elevation bin (two points just inside its edges): the mean of C/N0 minus each
    signal's offset over the bin, minus the fitted zenith C/N0; a bin without ``fidelity.by_elevation``'s
    minimum count takes the quadratic rolloff at its centre. Steps, not a line through the bins' centres: the
    satellites of a short file sit anywhere in their bin, and the comparison is per bin."""
    pooled = np.concatenate([cn0[g.name] - _cn0_offset(g, p) for g in sigs], axis=1)
    return _pattern(fidelity.by_elevation(pooled, np.tile(el, (1, len(sigs)))), p)


def _pattern(mean, p) -> tuple:
    """The step gain pattern of :func:`_gain_pattern` from C/N0 levels per 10-degree bin ``mean`` (None: the
    quadratic rolloff at the bin's centre)."""
    edges = fidelity.ELEVATION_EDGES_DEG
    off, gain = [], []
    for lo, hi, m in reversed(list(zip(edges[:-1], edges[1:], mean))):
        g = m - p["cn0_zenith_dbhz"] if m is not None else -p["rolloff_db"] * ((90.0 - 0.5 * (lo + hi)) / 90.0) ** 2
        off += [90.0 - hi + 0.01, 90.0 - lo - 0.01]
        gain += [float(g), float(g)]
    return tuple(float(x) for x in off), tuple(gain)


def rescale(p: dict, result: dict) -> dict:
    """``p`` with the carrier, Doppler and per-signal code terms scaled by real / twin of a twin run's
    comparison ``result`` (median over pairs, signals or elevation bins): PLL and FLL bandwidths by the squared
    ratio (jitter ~ sqrt(bandwidth)), carrier multipath and the code factors by the ratio."""
    p = dict(p)
    real, twin = result["real"], result["twin"]
    r = [real["carrier_noise_m"][k] / twin["carrier_noise_m"][k] for k in real["carrier_noise_m"]
         if np.isfinite(real["carrier_noise_m"][k]) and twin["carrier_noise_m"].get(k)]
    if r:
        p["pll_bandwidth_hz"] = float(np.clip(p["pll_bandwidth_hz"] * np.median(r) ** 2, 0.1, 100.0))
        p["mp_carrier_sigma_m"] = float(p["mp_carrier_sigma_m"] * np.median(r))
    r = [real["doppler_noise_hz"][k] / twin["doppler_noise_hz"][k] for k in real["doppler_noise_hz"]
         if np.isfinite(real["doppler_noise_hz"][k]) and twin["doppler_noise_hz"].get(k)]
    if r:
        p["fll_bandwidth_hz"] = float(np.clip(p["fll_bandwidth_hz"] * np.median(r) ** 2, 0.05, 100.0))
    scales = dict(p.get("code_error_scale", {}))
    for s, ratios in result["code_noise_ratio"].items():
        ok = [x for x in ratios if x]
        if ok and not isinstance(scales.get(s), tuple):
            scales[s] = float(scales.get(s, 1.0) / np.median(ok))
    p["code_error_scale"] = scales
    return p


def code_tables(p: dict, result: dict) -> dict:
    """``p`` with each signal's code factor turned into a table over the elevation bins' centres: the factor
    there divided by the twin / real code-noise ratio of that bin in the twin run ``result`` (made with ``p``);
    a bin without a ratio takes the signal's median ratio. Code noise and code multipath are both linear in the
    factor, so one step moves every bin onto the real sigma up to the two files' sampling scatter."""
    p = dict(p)
    edges = np.asarray(result["elevation_bins_deg"], float)
    centres = 0.5 * (edges[:-1] + edges[1:])
    scales = dict(p.get("code_error_scale", {}))
    for s, ratios in result["code_noise_ratio"].items():
        ok = [x for x in ratios if x]
        if not ok:
            continue
        now = np.broadcast_to(angle_table_at(scales.get(s, 1.0), np.radians(centres)), centres.shape)
        r = np.array([x if x else np.median(ok) for x in ratios])
        scales[s] = (tuple(float(c) for c in centres), tuple(float(f) for f in now / r))
    p["code_error_scale"] = scales
    return p


def _fit_code(st, sigs, centres, dll):
    """(sigma_h m, el0 deg, {signal: factor}) minimising the log misfit of the code scatter per signal and
    elevation bin to f_s sqrt(dll_s(el)^2 + sigma_h^2 exp(-2 el / el0)): one multipath profile, one factor per
    signal (scipy least squares); None with fewer bins than unknowns."""
    from scipy.optimize import least_squares

    rows = [(k, c, m, dll(g, c)) for k, g in enumerate(sigs)
            for m, c in zip(st["code_noise_robust_m"][g.name], centres) if m is not None and m > 0]
    used = sorted({k for k, *_ in rows})
    if len(rows) < len(used) + 3:
        return None
    k_of = np.array([used.index(k) for k, *_ in rows])
    el = np.array([c for _, c, _, _ in rows])
    meas = np.log([m for *_, m, _ in rows])
    white = np.array([w for *_, w in rows])

    def resid(x):
        sigma_h, el0 = np.exp(x[0]), np.exp(x[1])
        model = np.exp(x[2:])[k_of] * np.sqrt(white ** 2 + (sigma_h * np.exp(-el / el0)) ** 2)
        return np.log(model) - meas

    x0 = np.concatenate([[np.log(0.5), np.log(np.radians(20.0))], np.zeros(len(used))])
    lo = np.concatenate([[np.log(1e-3), np.log(np.radians(1.0))], np.full(len(used), np.log(1e-3))])
    hi = np.concatenate([[np.log(20.0), np.log(np.radians(90.0))], np.full(len(used), np.log(100.0))])
    x = least_squares(resid, x0, bounds=(lo, hi)).x
    return (float(np.exp(x[0])), float(np.degrees(np.exp(x[1]))),
            {sigs[k].name: float(np.exp(x[2 + i])) for i, k in enumerate(used)})


def toml_fragment(p: dict) -> str:
    """The fitted parameters as the [gnss] TOML fragment of a scenario (the calibrated twin)."""
    lines = ["# simkit twin --fit: [gnss] error parameters estimated from the real file (docs/real_data.md)", "[gnss]",
             f"cn0_zenith_dbhz = {p['cn0_zenith_dbhz']:.2f}", f"slip_rate_per_h = {p['slip_rate_per_h']:.3f}", "",
             "[gnss.noise]", 'model = "cn0"', f"dll_bandwidth_hz = {p['dll_bandwidth_hz']:.4f}",
             f"pll_bandwidth_hz = {p['pll_bandwidth_hz']:.4f}", f"fll_bandwidth_hz = {p['fll_bandwidth_hz']:.4f}", "",
             "[gnss.multipath]", f"code_sigma_m = {p['mp_code_sigma_m']:.4f}",
             f"carrier_sigma_m = {p['mp_carrier_sigma_m']:.5f}",
             f"elevation_scale_deg = {p['mp_elevation_scale_deg']:.2f}",
             f"correlation_time_s = {p['mp_correlation_time_s']:.1f}", "",
             "# each signal's multipath correlation time (s)", "[gnss.multipath.signal_correlation_time_s]",
             *(f"{k} = {v:.1f}" for k, v in p.get("mp_signal_correlation_time_s", {}).items()), "",
             "[gnss.code_error_scale]", *(f"{k} = {_table_toml(v, 'elevation_deg', 'factor', '.4f')}"
                                        for k, v in p.get("code_error_scale", {}).items()),
             "", "# the receiver's C/N0 per signal beyond the signal table's offsets (by the angle from boresight where "
             "one pattern does not serve every signal)",
             "[gnss.cn0_offset_db]", *(f"{k} = {_table_toml(v, 'off_boresight_deg', 'offset_db', '.2f')}"
                                     for k, v in cn0_offset_entries(p).items()),
             *_satellite_offsets_toml(p.get("satellite_cn0_offset_db", {})),
             "",
             "[[gnss.antenna]]", "lever_arm_m = [0.0, 0.0, 0.0]",
             f"rolloff_db = {p['rolloff_db']:.2f}" if not p.get("gain_pattern") else
             f"gain_pattern = {_table_toml(p['gain_pattern'], 'off_boresight_deg', 'gain_db', '.2f')}"]
    if p.get("iono_residual_fraction") is not None:
        lines += ["", "# the real ionosphere against Klobuchar (dual-frequency geometry-free, carrier-levelled code)",
                  "[gnss.truth_errors]", f"iono_residual_fraction = {p['iono_residual_fraction']:.4f}"]
    if p.get("truth_errors"):
        if p.get("iono_residual_fraction") is None:
            lines += ["", "[gnss.truth_errors]"]
        lines += ["# broadcast orbit/clock (SISRE) and troposphere from ionosphere-free code residuals (sisre.py)"]
        lines += [f"{k} = {_toml_value(v)}" for k, v in p["truth_errors"].items()]
    if p.get("shadowing"):
        sh = p["shadowing"]
        lines += ["", "# street shadowing: a Markov channel per satellite (line of sight / shadowed / blocked) from the "
                  "real C/N0 series (shadowing_fit.py)", "[gnss.shadowing]"]
        lines += [f"{k} = {_toml_list(v)}" for k, v in sh.items() if k != "systems"]
        for letter, table in sh.get("systems", {}).items():
            lines += [f"[gnss.shadowing.systems.{letter}]", *(f"{k} = {_toml_list(v)}" for k, v in table.items())]
    if p.get("cn0_report"):
        lines += ["", "# the receiver's C/N0 output step (the real file's values are multiples of it)",
                  "[gnss.cn0_report]", *(f"{k} = {v:g}" for k, v in p["cn0_report"].items())]
    if p.get("acquisition"):
        lines += ["", "# rising satellites: first tracked this long after they cross the mask (acquisition.py)",
                  "[gnss.acquisition]", f"delay_s = {p['acquisition']['delay_s']:.1f}"]
    if p.get("horizon_mask"):
        tab = p["horizon_mask"]
        lines += ["", "# the station's horizon profile (a level antenna facing north: body azimuth = azimuth)",
                  "[environment]", "reflections = false", "", "[[environment.body_mask]]",
                  f"azimuth_deg = [{', '.join(f'{a:g}' for a in tab['azimuth_deg'])}]",
                  f"elevation_deg = [{', '.join(f'{e:g}' for e in tab['elevation_deg'])}]"]
    return "\n".join(lines) + "\n"


def _toml_list(v) -> str:
    return "[" + ", ".join(f"{x:g}" for x in v) + "]" if isinstance(v, list) else _toml_value(v)


def _toml_value(v) -> str:
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(f"{x:.4f}" for x in v) + "]"
    return f"{v:.4f}"


def _satellite_offsets_toml(tables: dict) -> list:
    lines = ["", "# each satellite's C/N0 beyond the model, per signal (its power; at a station, its track)"] \
        if tables else []
    for name, table in tables.items():
        lines += [f"[gnss.satellite_cn0_offset_db.{name}]", *(f"{k} = {v:.2f}" for k, v in table.items())]
    return lines


def _table_entry(v, angle_key: str, value_key: str):
    """A number as it is, or an angle table (an (angles, values) pair, a list of two lists when read back from
    JSON) as the scenario's table {angle_key: [...], value_key: [...]}."""
    if isinstance(v, (tuple, list)):
        return {angle_key: list(v[0]), value_key: list(v[1])}
    return v


def _table_toml(v, angle_key: str, value_key: str, fmt: str) -> str:
    """A number, or an angle table (an (angles, values) pair, a list of two lists when read back from JSON, or the
    dict {angle_key: ..., value_key: ...}), as a TOML value; values written with ``fmt``."""
    if isinstance(v, dict):
        v = (v[angle_key], v[value_key])
    if isinstance(v, (tuple, list)):
        return (f"{{{angle_key} = [{', '.join(f'{a:g}' for a in v[0])}], "
                f"{value_key} = [{', '.join(format(x, fmt) for x in v[1])}]}}")
    return format(v, fmt)


def _twin_once(real, ref, nav_paths, mask, params, seed, path, progress, arrays=False):
    """One twin of ``real`` with ``params``: its comparison (and the real arrays on its grid and its own). The twin
    keeps only the epochs the real arrays have (``real`` may be a subset of a file's epochs: a split)."""
    from ..pipeline import run

    run(scenario(real, ref, nav_paths, mask, params, seed), out=path, progress=progress, force=True)
    twin = file_arrays(path)
    twin = _rows(twin, _align(real, twin)[1] >= 0)
    on_grid = on_twin_grid(real, twin)
    result = compare(on_grid, twin, ref, mask)
    return (result, on_grid, twin) if arrays else result


def _realisations(real, ref, nav_paths, mask, params, seeds, path, progress):
    """Twins of ``real`` with ``params`` for each of ``seeds``: (the real arrays on their grid, [twin arrays])."""
    runs = [_twin_once(real, ref, nav_paths, mask, params, s, path, progress, arrays=True) for s in seeds]
    return runs[0][1], [r[2] for r in runs]


def noise_check(real_grid: dict, twins: list, ref, mask: float, rows=None) -> dict:
    """:func:`.noise_fit.code_comparison` (equal-count bins, twin over its realisations) and
    :func:`.noise_fit.cn0_comparison` (the fixed bins) of the real arrays on the twins' grid against ``twins``,
    on the epochs ``rows`` (bool; all when None)."""
    if rows is not None:
        real_grid, twins = _rows(real_grid, rows), [_rows(t, rows) for t in twins]
    el = fidelity.elevations(twins[0]["sat_pos"], ref)

    def mp(a):
        return fidelity.multipath(a["obs"], a["signals"], np.asarray(a["sat_freq"]), a["t"])

    code = noise_fit.code_comparison(mp(real_grid), [mp(t) for t in twins], el, mask)
    cn0 = noise_fit.cn0_comparison(real_grid["obs"]["cn0"], [t["obs"]["cn0"] for t in twins], el,
                                   fidelity.ELEVATION_EDGES_DEG)
    return {"code_noise": code, "cn0": cn0, "epochs": int(twins[0]["t"].size)}


def fit_horizon(real_on_grid: dict, twin: dict, reference, mask_deg: float) -> dict:
    """The horizon profile (:mod:`.horizon`) from the real tracking on the twin's grid and the twin's geometry
    (``twin`` simulated without a profile): the ``[[environment.body_mask]]`` table, its in-sample agreement and
    the agreement fitted on one half of the epochs and checked on the other."""
    rx = np.broadcast_to(np.asarray(reference, float), (twin["t"].size, 3))
    with np.errstate(invalid="ignore"):
        el, az = angles_from_enu(lines_of_sight_enu(rx, twin["sat_pos"])[0])
    real_on, twin_on = fidelity.tracked(real_on_grid["obs"]), fidelity.tracked(twin["obs"])
    floor = np.radians(mask_deg)
    table = horizon.mask_table(horizon.profile(el, az, real_on, floor, simulated=twin_on))
    return {"table": table, "sector_deg": horizon.SECTOR_DEG,
            "in_sample": horizon.agreement(el, az, real_on, twin_on, floor, table),
            "holdout": horizon.holdout(el, az, real_on, twin_on, floor)}


def fit_acquisition(real_on_grid: dict, twin: dict, reference, mask_deg: float, table=None) -> dict:
    """The acquisition delay of rising satellites (:mod:`.acquisition`) from the real tracking on the twin's grid
    and the default twin ``twin`` (its geometry seen from ``reference``, cut by the horizon ``table`` if any)."""
    rx = np.broadcast_to(np.asarray(reference, float), (twin["t"].size, 3))
    with np.errstate(invalid="ignore"):
        el, az = angles_from_enu(lines_of_sight_enu(rx, twin["sat_pos"])[0])
    out = acquisition.fit(twin["t"], el, az, fidelity.tracked(twin["obs"]), fidelity.tracked(real_on_grid["obs"]),
                          mask_deg, table)
    for r in out["rising"]:
        r["sat"] = twin["sat_id"][r.pop("column")]
    return out


REALISATIONS = 4          # twins (seeds) whose pooled statistics are the twin's expectation in a noise check
CODE_MODELS = ("smooth", "bins")


def _calibrate(real, ref, nav_paths, mask, seed, path, progress, default=None, code_model="smooth",
               realisations=REALISATIONS, shadowing=True):
    """The fitted parameters of ``real`` (:func:`fit_parameters`, the horizon profile, then the carrier, Doppler
    and code terms scaled from a default and a first calibrated twin), the fit's notes and {"horizon":
    :func:`fit_horizon`, "ionosphere": the Klobuchar comparison of :func:`.ionosphere.klobuchar_ratio`};
    ``default`` = (comparison, real on the grid, twin arrays) of a default twin already run on ``real``.

    ``code_model``: "smooth" (the code factor per signal corrected by a line in elevation through the log
    twin / real ratios of ``realisations`` first twins in equal-count bins, :func:`.noise_fit.smooth_correction`:
    two parameters per signal) or "bins" (a free factor per 10-degree bin from one first twin,
    :func:`code_tables`)."""
    if code_model not in CODE_MODELS:
        raise InputError("code_model", f"expected one of {', '.join(CODE_MODELS)}, got {code_model!r}")
    if default is None:
        default = _twin_once(real, ref, nav_paths, mask, DEFAULTS, seed, path, progress, arrays=True)
    fitted = fit_parameters(real, ref)
    notes = fitted.pop("_notes")
    iono = fitted.pop("_ionosphere", None)
    range_errors = fitted.pop("_sisre", None)
    hz = None
    if not real.get("trajectory"):       # a horizon profile belongs to a fixed antenna
        hz = fit_horizon(default[1], default[2], ref, mask)
        fitted["horizon_mask"] = hz["table"]
    acq = fit_acquisition(default[1], default[2], ref, mask, hz["table"] if hz else None)
    if acq["delay_s"] > 0:
        fitted["acquisition"] = {"delay_s": acq["delay_s"]}
    shadow = fit_shadowing(default[1], default[2], ref, fitted) if shadowing and real.get("trajectory") else None
    if shadow is not None:           # a drive: the line-of-sight pattern, and the street's losses as a channel
        fitted["shadowing"] = shadow["config"]
        shift = shadow["los_offset_db"]
        first = [k for k in real["signals"] if k in shift and k not in fitted.get("cn0_offset_db", {})]
        ref_shift = shift[first[0]] if first else 0.0     # the first signal carries no fitted offset
        fitted["cn0_offset_db"] = {k: v + shift.get(k, ref_shift) - ref_shift
                                   for k, v in fitted.get("cn0_offset_db", {}).items()}
        fitted["gain_pattern"] = _pattern([None if v is None else v + ref_shift for v in shadow["level_dbhz"]],
                                          fitted)
    code_fit = dict(fitted.get("code_error_scale", {}))
    fitted = rescale(fitted, default[0])              # carrier and Doppler terms from the default twin
    if code_model == "bins":
        first = _twin_once(real, ref, nav_paths, mask, fitted, seed + 1, path, progress)
        tables = code_tables(fitted, first)["code_error_scale"]    # code factors per elevation bin
        fitted = {**rescale(fitted, first), "code_error_scale": tables}   # carrier and Doppler refined
    else:
        # the first twin starts from the code fit itself: the default twin's code ratios belong to the default
        # multipath profile, and dividing the fitted factors by them left factors 10x too small, where the
        # carrier terms of the MP combination (not scaled by the factor) rule the twin's sigma and a one-step
        # linear correction overshoots
        fitted["code_error_scale"] = code_fit
        grid, twins = _realisations(real, ref, nav_paths, mask, fitted,
                                    [seed + 1 + 100 * k for k in range(realisations)], path, progress)
        first = compare(grid, twins[0], ref, mask)
        code = noise_check(grid, twins, ref, mask)["code_noise"]["signals"]
        tables = noise_fit.smooth_correction(code, fitted.get("code_error_scale", {}))
        fitted = rescale(fitted, first)
        fitted["code_error_scale"] = {**fitted["code_error_scale"], **tables}
    return fitted, notes, {"horizon": hz, "ionosphere": iono, "sisre_troposphere": range_errors, "acquisition": acq,
                           "shadowing": shadow}


def fit_shadowing(real_on_grid: dict, twin: dict, reference, p: dict) -> dict | None:
    """The street-shadowing channel (:mod:`.shadowing_fit`) of the real C/N0 on the twin's grid, above the mask
    where the default twin ``twin`` tracks, with the signals' C/N0 offsets of the fitted parameters ``p``."""
    el = fidelity.elevations(twin["sat_pos"], reference)
    dt = float(np.median(np.diff(twin["t"]))) if twin["t"].size > 1 else 1.0
    offsets = {s: _cn0_offset(sigmod.get(s), p) for s in real_on_grid["signals"]}
    # one state-probability table for all systems: tables per system (shadowing_fit.fit's ``systems``) did not bring
    # GLONASS closer on Berlin and took it further on its 12 s test copy (docs/shadowing.md)
    return shadowing_fit.fit(real_on_grid["obs"]["cn0"], offsets, el, fidelity.tracked(twin["obs"]), dt)


def _rows(arr: dict, rows) -> dict:
    """``arr`` (a twin or real dict) cut to the epochs ``rows`` (bool (M,))."""
    return {**arr, "t": arr["t"][rows], "sat_pos": arr["sat_pos"][rows],
            **({"sat_clock": arr["sat_clock"][rows]} if arr.get("sat_clock") is not None else {}),
            "obs": {k: {s: v[rows] for s, v in d.items()} for k, d in arr["obs"].items()}}


SPLITS = ("half", "interleaved")
MAX_BLOCKS = 6


def split_rows(t, kind: str):
    """The epochs (bool (M,)) a split fits on; the others are checked. "half": the first half of the span.
    "interleaved": the span cut into equal blocks, as many as leave each block at least ``fidelity.MIN_ARC`` + 1
    epochs (at most ``MAX_BLOCKS``, at least 3), fitted on the even blocks and checked on the odd ones: along a
    drive the environment changes, and a first / second half split mixes that change with the model's error."""
    t = np.asarray(t, float)
    span = t[-1] - t[0]
    if kind == "half":
        return t < t[0] + 0.5 * span
    if kind != "interleaved":
        raise InputError("split", f"expected one of {', '.join(SPLITS)}, got {kind!r}")
    n = int(np.clip(t.size // (fidelity.MIN_ARC + 1), 3, MAX_BLOCKS))
    block = np.minimum(np.floor((t - t[0]) / span * n), n - 1) if span > 0 else np.zeros(t.size)
    return block % 2 == 0


def _holdout(real, ref, nav_paths, mask, seed, path, progress, split="half", code_model="smooth",
             realisations=REALISATIONS, shadowing=True) -> dict:
    """Out-of-sample check of the fit: every parameter (horizon profile and code tables included) fitted on the
    epochs :func:`split_rows` keeps, twins of the whole span run with them (``realisations`` seeds), and the
    comparison on the other epochs (neither the fit nor its twins saw them)."""
    fit_rows = split_rows(real["t"], split)
    fitted, _, extras = _calibrate(_rows(real, fit_rows), ref, nav_paths, mask, seed + 10, path, progress,
                                   code_model=code_model, realisations=realisations, shadowing=shadowing)
    grid, twins = _realisations(real, ref, nav_paths, mask, fitted,
                                [seed + 12 + 100 * k for k in range(realisations)], path, progress)
    check = ~fit_rows[np.clip(_align(real, twins[0])[1], 0, None)]
    out = compare(_rows(grid, check), _rows(twins[0], check), ref, mask)
    tc = twins[0]["t"]
    return {"split": split, "code_model": code_model,
            "fitted_on_s": [float(x) for x in real["t"][fit_rows][[0, -1]]],
            "checked_on_s": [float(x) for x in tc[check][[0, -1]]], "checked_epochs": int(check.sum()),
            "visibility_agreement": out["visibility_agreement"],
            "satellite_epochs_above_mask": out["satellite_epochs_above_mask"],
            "tracked_real_not_twin": out["tracked_real_not_twin"], "tracked_twin_not_real": out["tracked_twin_not_real"],
            "code_noise_ratio": out["code_noise_ratio"], "real_code_noise_m": out["real"]["code_noise_m"],
            "cn0_rms_difference_dbhz": out["cn0_rms_difference_dbhz"],
            "twin_code_noise_m": out["twin"]["code_noise_m"], "horizon_table": (extras["horizon"] or {}).get("table"),
            "iono_residual_fraction": fitted.get("iono_residual_fraction"),
            "shadowing": fitted.get("shadowing"),
            "noise": _with_drift(noise_check(grid, twins, ref, mask, rows=check), _rows(grid, ~check), ref)}


def _with_drift(check: dict, other: dict, ref) -> dict:
    """``check`` (a :func:`noise_check` on some epochs) with the real file's own drift against the ``other``
    epochs (:func:`.noise_fit.drift`)."""
    mp = fidelity.multipath(other["obs"], other["signals"], np.asarray(other["sat_freq"]), other["t"])
    el = fidelity.elevations(other["sat_pos"], ref)
    check["code_noise"]["real_drift"] = noise_fit.drift(check["code_noise"]["signals"], mp, el)
    for s, c in check["cn0"].items():
        c["real_against_itself"] = noise_fit.cn0_drift(c["bins"], other["obs"]["cn0"][s], el)
    return check


def track_sigma_enu(pos_ecef, centre, window: int = 51) -> list:
    """Position noise [east, north, up] (m) of a logged track: the robust standard deviation (1.4826 MAD) of its
    samples about their running median over ``window`` samples (10 s of a 5 Hz log). A receiver's own SPP
    errors are correlated over seconds, so the third differences the log fit estimates its noise from see only
    a fraction of them, and the fitted path (and the attitude that follows its velocity) would keep them."""
    from scipy.ndimage import median_filter

    p = np.asarray(pos_ecef, float)
    p = p[np.isfinite(p).all(axis=1)]
    lla = frames.ecef_to_lla(np.asarray(centre, float)[None])[0]
    enu = (p - centre) @ frames.ecef_to_enu_matrix(lla[0], lla[1]).T
    r = enu - median_filter(enu, size=(min(window, len(enu)), 1), mode="nearest")
    return [float(max(x, 0.01)) for x in 1.4826 * np.median(np.abs(r - np.median(r, axis=0)), axis=0)]


def level_track_csv(rec, centre, name: str) -> str:
    """The log ``rec`` (a :class:`simkit.logs.Record`) as the CSV log of a vehicle on level ground: its epochs
    and horizontal positions, every height the median height, and the position noise of :func:`track_sigma_enu`
    in ``sd_*`` columns. A car's SPP heights scatter by metres from epoch to epoch, and a path through them
    would pitch the antenna by tens of degrees (the "ground" attitude follows the velocity), moving C/N0 with it."""
    p = np.asarray(rec.pos_ecef, float)
    ok = np.isfinite(p).all(axis=1)
    sd = track_sigma_enu(p[ok], centre)
    lla = frames.ecef_to_lla(p[ok])
    h = float(np.median(lla[:, 2]))
    rows = [f"{w:d},{s:.4f},{np.degrees(la):.9f},{np.degrees(lo):.9f},{h:.3f},{sd[0]:.3f},{sd[1]:.3f},0.010"
            for w, s, la, lo in zip(np.asarray(rec.week)[ok], np.asarray(rec.sow)[ok], lla[:, 0], lla[:, 1])]
    return "\n".join([f"# {name}: horizontal positions, heights set to their median (simkit twin)",
                      "gps_week,gps_sow,lat_deg,lon_deg,h_m,sd_e_m,sd_n_m,sd_u_m", *rows]) + "\n"


def _fit_and_check(real, ref, nav_paths, mask, seed, out_dir, progress, default, code_model, realisations,
                   shadowing=True) -> dict:
    """--fit of :func:`run_twin`: the calibrated twin (fitted.toml, twin_fit.h5), its comparison and noise checks in
    sample, and the two out-of-sample splits; the entries of the fidelity dict."""
    result = {}
    fitted, notes, extras = _calibrate(real, ref, nav_paths, mask, seed, out_dir / "twin_fit.h5", progress,
                                       default, code_model, realisations, shadowing)
    result.update(extras)
    result["fit_notes"] = notes
    result["fitted_parameters"] = fitted
    (out_dir / "fitted.toml").write_text(toml_fragment(fitted))
    # the last realisation written (twin_fit.h5) is the seed + 2 twin of the fixed-bin comparison
    grid, twins = _realisations(real, ref, nav_paths, mask, fitted,
                                [seed + 2 + 100 * k for k in reversed(range(realisations))],
                                out_dir / "twin_fit.h5", progress)
    result["fitted"] = compare(grid, twins[-1], ref, mask)
    result["noise"] = {"in_sample": noise_check(grid, twins, ref, mask), "code_model": code_model,
                       "twin_realisations": realisations}
    result["holdout"] = _holdout(real, ref, nav_paths, mask, seed, out_dir / "twin_holdout.h5", progress,
                                 "half", code_model, realisations, shadowing)
    result["holdout_interleaved"] = _holdout(real, ref, nav_paths, mask, seed, out_dir / "twin_holdout.h5",
                                             progress, "interleaved", code_model, realisations, shadowing)
    return result


def run_twin(obs_path, nav_paths, out_dir, fit: bool = False, seed: int = 1, reference=None,
             reference_source=None, progress: bool = False, trajectory=None, trajectory_solution=None,
             code_model: str = "smooth", realisations: int = REALISATIONS, shadowing: bool = True) -> dict:
    """Import ``obs_path`` (+ ``nav_paths``), simulate its twin into ``out_dir``/twin.h5 (and with ``fit`` the
    calibrated twin_fit.h5), compare; returns the fidelity dict (also the content of fidelity.json).

    ``trajectory``: a log of the receiver's path (any ``[trajectory] source``: e.g. the real file's own SPP
    solution, ``real.h5`` with ``trajectory_solution="spp"``): the twin of a moving receiver. Its outlying
    samples are dropped (``outliers = "drop"``); elevations for the statistics are taken from the log's median
    position (a car's few hundred metres move them by less than 0.01 deg) and no horizon profile is fitted.

    ``code_model`` and ``realisations``: :func:`_calibrate`'s; the calibrated twin is checked in sample and out of
    sample on both :data:`SPLITS` (``holdout``: half, ``holdout_interleaved``) over ``realisations`` seeds
    (:func:`noise_check`). ``shadowing``: with a ``trajectory``, fit the street-shadowing channel
    (:func:`fit_shadowing`, ``[gnss.shadowing]``) into the calibrated twin; False keeps the C/N0 an elevation
    model only."""
    out_dir = Path(out_dir)
    if not nav_paths:
        raise InputError("--nav", "the twin needs the broadcast navigation file(s) of the observation file")
    if int(realisations) < 1:
        raise InputError("--realisations", f"expected a number of twins >= 1, got {realisations}")
    imported = importer.import_rinex(obs_path, nav_paths, reference, reference_source)
    real = real_arrays(imported)
    ref = real["reference"]
    out_dir.mkdir(parents=True, exist_ok=True)
    if trajectory is not None:
        from ..logs import read

        rec = read(Path(trajectory), solution=trajectory_solution)
        ref = np.nanmedian(rec.pos_ecef, axis=0)
        (out_dir / "trajectory.csv").write_text(level_track_csv(rec, ref, Path(trajectory).name))
        real["trajectory"] = {"source": str((out_dir / "trajectory.csv").resolve()), "outliers": "drop",
                              "attitude": "ground"}
    elif ref is None:
        raise InputError(str(obs_path), "no reference position (no APPROX POSITION XYZ in the header): give "
                                        "--reference X,Y,Z, or the receiver's path with --trajectory LOG (a moving "
                                        "receiver, e.g. the file's SPP solution: docs/real_data.md)")
    importer.write(out_dir / "real.h5", imported)
    mask = inferred_mask_deg(real, ref)
    result = {"obs": Path(obs_path).name, "nav": [Path(n).name for n in nav_paths],
              "reference": imported.report["reference"] if trajectory is None else
              f"moving: the path of {Path(trajectory).name}" + (f" /solutions/{trajectory_solution}"
                                                               if trajectory_solution else ""), "epochs": int(real["t"].size),
              "span_s": float(real["t"][-1]), "signals": real["signals"], "seed": seed}
    result["default"], real_grid, twin0 = _twin_once(real, ref, nav_paths, mask, DEFAULTS, seed,
                                                      out_dir / "twin.h5", progress, arrays=True)
    if fit:
        default = (result["default"], real_grid, twin0)
        result.update(_fit_and_check(real, ref, nav_paths, mask, seed, out_dir, progress, default, code_model,
                                     realisations, shadowing))
        if shadowing and result.get("shadowing"):      # the same checks without the term, side by side in report.md
            sub = out_dir / "without_shadowing"
            sub.mkdir(exist_ok=True)
            result["without_shadowing"] = _fit_and_check(real, ref, nav_paths, mask, seed, sub, progress, default,
                                                         code_model, realisations, False)
    (out_dir / "fidelity.json").write_text(json.dumps(result, indent=1))
    return result


def _fmt(v, digits=2):
    return "-" if v is None or (isinstance(v, float) and not np.isfinite(v)) else f"{v:.{digits}f}"


def report_markdown(fid: dict, figures=()) -> str:
    """report.md of a twin: the comparison tables of :func:`compare` for the default (and fitted) twin."""
    runs = [k for k in ("default", "fitted") if k in fid]
    base = fid[runs[0]]
    edges = base["elevation_bins_deg"]
    bins = [f"{a:g}-{b:g}" for a, b in zip(edges[:-1], edges[1:])]
    out = [f"# Twin of {fid['obs']}", "",
           f"Navigation: {', '.join(fid['nav'])}. Reference: {fid['reference']}. {fid['epochs']} epochs over "
           f"{fid['span_s']:.0f} s; signals {', '.join(fid['signals'])}; elevation mask inferred from the data: "
           f"{base['mask_deg']:g} deg. Twin: simkit defaults" + (", and the calibrated twin (--fit, "
                                                                  "fitted.toml)." if "fitted" in fid else "."), ""]
    out += ["## Tracking", "", "| twin | visibility agreement | satellite-epochs above the mask | tracked real only "
            "| tracked twin only | highest elevation of a disagreement (deg) | tracked per epoch real / twin |",
            "|---|---:|---:|---:|---:|---:|---|"]
    for k in runs:
        c = fid[k]
        out.append(f"| {k} | {_fmt(100 * c['visibility_agreement'], 1)} % | {c['satellite_epochs_above_mask']} | "
                   f"{c['tracked_real_not_twin']} | {c['tracked_twin_not_real']} | "
                   f"{_fmt(c['disagreement_max_elevation_deg'], 1)} | {_fmt(c['real']['tracked_per_epoch']['mean'], 1)}"
                   f" / {_fmt(c['twin']['tracked_per_epoch']['mean'], 1)} |")
    for quantity, title, digits in (("cn0_dbhz", "C/N0 (dB-Hz), mean per elevation bin (deg)", 1),
                                    ("code_noise_m", "Code noise and multipath sigma (m) per elevation bin (deg), "
                                     "from the code-minus-carrier", 3)):
        out += ["", f"## {title}", "", "| signal | file | " + " | ".join(bins) + " |",
                "|---|---|" + "---:|" * len(bins)]
        for s in fid["signals"]:
            out.append(f"| {s} | real | " + " | ".join(_fmt(v, digits) for v in base["real"][quantity][s]) + " |")
            for k in runs:
                out.append(f"| {s} | twin ({k}) | " + " | ".join(_fmt(v, digits) for v in fid[k]["twin"][quantity][s])
                           + " |")
    out += ["", "C/N0 RMS difference over the bins (dB-Hz): " + "; ".join(
        f"{k}: " + ", ".join(f"{s} {_fmt(v)}" for s, v in fid[k]["cn0_rms_difference_dbhz"].items()) for k in runs)]
    out += ["", "Code-noise ratio twin / real per bin: " + "; ".join(
        f"{k}: {_within(fid[k]['code_noise_ratio'])}" for k in runs)]
    out += ["", "## Carrier, Doppler, slips", "", "| quantity | real | " + " | ".join(f"twin ({k})" for k in runs)
            + " |", "|---|---:|" + "---:|" * len(runs)]
    for key, label, d in (("carrier_noise_m", "carrier noise (m, geometry-free 3rd difference / sqrt 20)", 4),
                          ("doppler_noise_hz", "Doppler noise (Hz)", 3), ("slips_per_hour", "LLI slips per hour", 2)):
        for s, v in base["real"][key].items():
            out.append(f"| {label} {s} | {_fmt(v, d)} | " + " | ".join(_fmt(fid[k]["twin"][key].get(s), d)
                                                                       for k in runs) + " |")
    out += noise_markdown(fid)
    if "fitted_parameters" in fid:
        out += ["", "## Fitted [gnss] parameters", "", "```toml", toml_fragment(fid["fitted_parameters"]).rstrip(),
                "```"] + [f"- {n}" for n in fid.get("fit_notes", [])]
    out += sisre.report_lines(fid.get("sisre_troposphere")) + acquisition.report_lines(fid.get("acquisition"))
    out += shadowing_markdown(fid)
    sh = fid.get("shadowing")
    if sh:
        c = sh["config"]
        out += ["", "## Street shadowing (fitted)", "",
                f"Satellite-epochs above the mask: {sh['state_counts'][0]} line of sight, {sh['state_counts'][1]} "
                f"shadowed, {sh['state_counts'][2]} blocked; mean dwell (s) {', '.join(f'{d:.1f}' for d in c['dwell_s'])}"
                f"; attenuation {c['attenuation_mean_db']:.1f} ± {c['attenuation_sigma_db']:.1f} dB, correlation "
                f"{c['attenuation_correlation_s']:.1f} s; line-of-sight C/N0 spread {sh['los_sd_db']:.1f} dB "
                "(not simulated: the twin's C/N0 is noiseless)."]
    out += [""] + [f"![{Path(p).stem}]({Path(p).name})" for p in figures]
    return "\n".join(out) + "\n"


def _noise_sections(fid: dict) -> list:
    """[(title, noise check dict)] of a fitted twin: in sample and on the two out-of-sample splits."""
    out = []
    if "noise" in fid:
        out.append(("in sample (the calibrated twin against the epochs it was fitted on)", fid["noise"]["in_sample"]))
    for key in ("holdout", "holdout_interleaved"):
        h = fid.get(key) or {}
        if "noise" in h:
            out.append((f"out of sample, {h['split']} split (fitted on {h['fitted_on_s'][0]:g}-{h['fitted_on_s'][1]:g} s"
                        f"{' in alternate blocks' if h['split'] == 'interleaved' else ''}, checked on "
                        f"{h['checked_epochs']} other epochs)", h["noise"]))
    return out


def _drift_line(d) -> str:
    if not d or not d.get("bins"):
        return ""
    return (f" The real file against itself (its sigma on these epochs over its sigma on the epochs fitted on, same "
            f"bins): {d['within']} of {d['bins']} bins within 20 %, {d['beyond_two_se']} beyond two standard "
            f"errors, median {_fmt(d['median_drift'])}.")


def noise_markdown(fid: dict) -> list:
    """The per-bin code-noise and C/N0 tables of :func:`noise_check` with their uncertainties (report.md)."""
    sections = _noise_sections(fid)
    if not sections:
        return []
    k = fid["noise"]["twin_realisations"]
    out = ["", "## Code noise and C/N0 with their uncertainties", "",
           f"Equal-count elevation bins per signal (at least {noise_fit.N_EFF_MIN:g} effective values each where the data have them), the twin pooled over "
           f"{k} realisations (seeds); code-noise model: {fid['noise']['code_model']}. ± is the relative standard "
           "error of the ratio: the real side's the larger of 1/sqrt(2 n_eff) (n_eff from the lag-one "
           "autocorrelation) and the jackknife over satellites. C/N0: the fixed 10-degree bins over the "
           "satellite-epochs both track; ± the standard error of the difference."]
    for title, sec in sections:
        sm = sec["code_noise"]["summary"]
        out += ["", f"### {title[0].upper()}{title[1:]}", "",
                f"Code noise: {sm.get('within', 0)} of {sm['bins']} bins within 20 % (a twin equal to the receiver in "
                f"expectation: about {_fmt(sm.get('expected_within_if_equal'), 1)} with these standard errors); "
                f"{sm.get('resolved', 0)} bins resolve 20 % (standard error <= 10 %), {sm.get('within_of_resolved', 0)} of "
                f"them within; {sm.get('beyond_two_se', 0)} bins differ by more than two standard errors; chi-square "
                f"per bin {_fmt(sm.get('chi2_per_bin'))}." + _drift_line(sec["code_noise"].get("real_drift")), "",
                "| signal | elevation (deg) | real σ (m) | n / n_eff | twin σ (m) | twin / real | ± |",
                "|---|---|---:|---:|---:|---:|---:|"]
        for sig, v in sec["code_noise"]["signals"].items():
            for b in v["bins"]:
                out.append(f"| {sig} | {b['bin_deg'][0]:.1f}-{b['bin_deg'][1]:.1f} | {_fmt(b['real_m'], 3)} | "
                           f"{b['real_n']} / {b['real_n_eff']:.0f} | {_fmt(b['twin_m'], 3)} | {_fmt(b['ratio'])} | "
                           f"{_fmt(b['ratio_rel_se'])} |")
        for sig, c in sec["cn0"].items():
            out += ["", f"C/N0 {sig}: {_cn0_summary(c, ' over the bins')}" + _cn0_drift_line(c.get("real_against_itself"))
                    + f". Spread within the bins (standard deviation of C/N0), twin - real: RMS "
                    f"{_fmt(c.get('spread_rms_db'))} dB", "",
                    "| elevation (deg) | real (dB-Hz) | satellites | twin | twin - real | ± | real sd | twin sd |",
                    "|---|---:|---:|---:|---:|---:|---:|---:|"]
            for b in c["bins"]:
                if b["difference"] is not None:
                    out.append(f"| {b['bin_deg'][0]:g}-{b['bin_deg'][1]:g} | {_fmt(b['real_dbhz'], 1)} | "
                               f"{b['real_satellites']} | {_fmt(b['twin_dbhz'], 1)} | {_fmt(b['difference'], 1)} | "
                               f"{_fmt(b['difference_se'], 1)} | {_fmt(b.get('real_sd_db'), 1)} | "
                               f"{_fmt(b.get('twin_sd_db'), 1)} |")
    return out


def _cn0_rows(fid: dict) -> dict:
    """{(comparison, signal): (C/N0 comparison, visibility agreement)} of a fitted twin's noise checks."""
    out = {}
    for title, sec in _noise_sections(fid):
        key = title.split(" (")[0]
        vis = fid["fitted"] if key == "in sample" else next(
            fid[k] for k in ("holdout", "holdout_interleaved") if fid.get(k, {}).get("noise") is sec)
        for sig, c in sec["cn0"].items():
            out[(key, sig)] = (c, vis["visibility_agreement"])
    return out


def shadowing_markdown(fid: dict) -> list:
    """report.md's table of the C/N0 comparisons with and without the street-shadowing term (docs/shadowing.md),
    with the real file against itself beside: RMS over the bins of the bin means (chi-square per bin), RMS of the
    spreads within the bins, visibility agreement."""
    if "without_shadowing" not in fid:
        return []
    on, off = _cn0_rows(fid), _cn0_rows(fid["without_shadowing"])
    out = ["", "## C/N0 with and without the street-shadowing term", "",
           "RMS over the 10-degree bins of twin - real bin means (chi-square per bin), and of the C/N0 spreads within "
           "the bins; the real file against itself on the splits (docs/shadowing.md).", "",
           "| comparison | signal | without: means | spread | visibility | with: means | spread | visibility | "
           "real against itself |", "|---|---|---:|---:|---:|---:|---:|---:|---:|"]

    def cell(c):
        return f"{_fmt(c['rms_dbhz'])} ({_fmt(c['chi2_per_bin'])})"

    for key, (c_on, v_on) in on.items():
        if key not in off:
            continue
        c_off, v_off = off[key]
        rr = c_on.get("real_against_itself") or {}
        out.append(f"| {key[0]} | {key[1]} | {cell(c_off)} | {_fmt(c_off.get('spread_rms_db'))} | "
                   f"{_fmt(100 * v_off, 1)} % | {cell(c_on)} | {_fmt(c_on.get('spread_rms_db'))} | "
                   f"{_fmt(100 * v_on, 1)} % | {cell(rr) if rr.get('bins') else '-'} |")
    return out


def _cn0_drift_line(d) -> str:
    if not d or not d.get("bins"):
        return ""
    return ("; the real file against itself (its bin means here minus those on the epochs fitted on, same bins): "
            + _cn0_summary(d))


def _cn0_summary(c, where: str = "") -> str:
    """Bias, scatter and RMS of a C/N0 comparison with the RMS of sampling alone and chi-square per bin."""
    return (f"bias {_fmt(c['bias_dbhz'])}, scatter {_fmt(c['scatter_dbhz'])}, RMS {_fmt(c['rms_dbhz'])} dB-Hz{where} "
            f"(sampling alone: {_fmt(c['rms_se_dbhz'])}; chi-square per bin {_fmt(c['chi2_per_bin'])})")


def _within(ratios: dict, tol: float = 0.2) -> str:
    vals = [x for v in ratios.values() for x in v if x is not None]
    if not vals:
        return "no bin"
    inside = sum(abs(x - 1.0) <= tol for x in vals)
    return f"{inside} of {len(vals)} bins within {100 * tol:g} % (median ratio {np.median(vals):.2f})"
