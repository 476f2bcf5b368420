"""Broadcast orbit/clock error (SISRE) and the zenith troposphere error of a static receiver with a known position.

Residuals. Per system (GPS, BDS) the first two signals on different frequencies give the ionosphere-free code
P_IF (the first-order ionosphere removed), in metres:

    y = P_IF - GD_IF + c dT^s - rho - T_model(el) = c dt_sys(t) + b_u + dT_z m(el) + e

rho the range from the reference to the broadcast satellite position at emission with the Sagnac term, dT^s the
broadcast clock, GD_IF the combination's group delay of the navigation data (/gnss/group_delay; zero for GPS
L1/L2, whose broadcast clock refers to that combination), T_model the receiver's Saastamoinen 1/sin(el)
troposphere (:func:`simkit.gnss.atmosphere.troposphere`). What is left: the receiver clock of the system,
per satellite pass (a *unit*: a contiguous pass, cut where an ephemeris interval ends) a bias b_u = the
orbit and clock error projected on the line of sight (the SISRE's sample), the zenith delay error dT_z mapped with
m(el), and code noise and multipath e. Where the carrier is continuous the code is levelled to it over the arc
(carrier-smoothed: P_IF's arc mean on the carrier's shape), so e within an arc is the carrier's; the arc mean still
carries the code noise and multipath averaged over the arc, which is accounted for below.

Separation (the clock and 1/sin(el) are correlated: both are common to a system's satellites at high elevation):

1. Per system, y = c(t) + b_u by least squares (alternating means, the two-way layout with missing cells); b_u is
   known up to the system's mean, which the clock takes: the b_u are centred per system. The same linear
   operator applied to m(el) gives each unit's mapped coefficient x_u, so that b_hat_u = b_u + dT_z x_u + noise,
   exactly, whatever the epochs each satellite covers (above 10 deg by default).
2. The unit biases as random effects: b_hat_u = a_sys + dT_z x_u - e_u . dr + r_u with r_u ~ N(0, s_k^2 + n_u),
   a_sys one intercept per clock system, e_u the unit's line of sight through the same operator and dr an offset
   of the reference (so that a reference wrong by a metre does not pass for orbit error), s_k^2 the SISRE^2 of the
   unit's orbit class k (GPS, BDS MEO, BDS GEO/IGSO: geosynchronous radius), n_u the noise variance of the unit's
   arc mean (its code-minus-carrier scatter over the arc, inflated for the lag-one correlation of multipath:
   s^2 / n (1 + rho) / (1 - rho)). Weighted least squares for (a, dr, dT_z) alternated with s_k^2 by the method
   of moments (sum r^2 / (s_k^2 + n) = dof: the class's units less its share of the parameters; Paule and
   Mandel 1982). The clock never enters (it is centred out at every epoch) and a pass's bias is decorrelated
   from its elevation because it is zero-mean over the satellites: that is what separates dT_z from the clock.
   The SISRE's uncertainty is the chi-square sampling of a variance from dof residuals, carried to the standard
   deviation; dT_z's is the weighted regression's.

The troposphere: two hypotheses are fitted, the truth mapped like the receiver's model (1/sin(el): ``"model"``)
or with the Niell (1996) functions (``"niell"``: the model's zenith delays mapped with Niell removed first, then
dT_z with the Niell functions); ``tropo_mapping`` is decided only when their -2 log-likelihoods differ by more
than ``LIKELIHOOD_MARGIN`` (the difference is metres below 10 deg elevation; minutes of data with few low passes
rarely decide it). A constant zenith offset dT_z is one draw of the truth's dZHD + dZWD, not their sigma: the
fragment writes tropo_zhd_sigma_m and tropo_zwd_sigma_m only when |dT_z| exceeds twice its uncertainty (then split
in the defaults' proportion, their root sum of squares = |dT_z|), and the random walk is not identifiable from a
file of minutes (kept at the default). The SISRE scales the system's orbit and clock sigmas together by
SISRE_fit / SISRE_default (one station cannot separate orbit from clock; BDS from its MEO class, and
``bds_geo_igso_sigma_scale`` = GEO/IGSO over MEO), with the global-average weights of Montenbruck et al. (2018):
w_R = 0.98, w_A,C^2 = 1/49 (GPS) and 0.98, 1/54 (BDS MEO).

Limits: the broadcast group delays are good to a few decimetres; C1C's differential code bias to P1 (decimetres)
is not removed and lands in the SISRE; BDS GEO/IGSO passes get the MEO weights; a receiver antenna's phase
centre variation (millimetres to centimetres) goes into dT_z and the SISRE.
"""
from __future__ import annotations

import numpy as np

from .. import gpstime
from ..earth import C_LIGHT
from ..gnss import atmosphere
from ..gnss.tropo_truth import niell_mapping
from ..gnss.truth_config import realistic_defaults
from . import fidelity
from ..gnss.spp import ranges_and_lines_of_sight
from .ionosphere import dual_frequency_pair, level_to_carrier

SYSTEMS = {"G": "gps", "C": "bds"}
SISRE_WEIGHTS = {"G": (0.98, 1.0 / 49.0), "C": (0.98, 1.0 / 54.0)}   # (w_R, w_AC^2), Montenbruck et al. 2018
MIN_UNITS = 8
MIN_EPOCHS = 3
GEOSYNC_RADIUS_M = 40.0e6    # BDS GEO and IGSO orbit at 42,164 km, MEO at 27,906 km
CLASS_NAMES = {"G": "GPS", "C": "BDS MEO", "C_geo": "BDS GEO/IGSO"}
LIKELIHOOD_MARGIN = 4.0     # -2 log L difference that decides the mapping (about 2 sigma)


def sisre_of(orbit_sigma_rac_m, clock_sigma_m, system: str) -> float:
    """Global-average SISRE (m) of independent orbit (R, A, C) and clock errors of RMS ``orbit_sigma_rac_m`` (3,)
    m and ``clock_sigma_m`` m: sqrt((w_R sigma_R)^2 + sigma_clk^2 + w_AC^2 (sigma_A^2 + sigma_C^2))."""
    w_r, w_ac = SISRE_WEIGHTS[system]
    r, a, c = orbit_sigma_rac_m
    return float(np.sqrt((w_r * r) ** 2 + clock_sigma_m ** 2 + w_ac * (a ** 2 + c ** 2)))


def residuals(real: dict, reference, elevation_cut_deg: float = 10.0) -> dict:
    """Ionosphere-free code residuals of ``real`` (the dict of :func:`.twin.real_arrays`, with ``sat_clock``
    (M, S) s and ``group_delay`` (S, G) m) at the static ``reference`` (3,) m ECEF, for the GPS and BDS satellites
    above ``elevation_cut_deg``: {y (M, S) m (NaN where none), noise_var (M, S) m^2 of the arc mean the epoch belongs
    to, unit (M, S) int (-1 none), el (M, S) rad, system (S,), lat, h, doy, pairs {system: [sig, sig]}}."""
    import pymap3d

    signals, freq, t = real["signals"], np.asarray(real["freq"], float), real["t"]
    ref = np.asarray(reference, float)
    sat = real["sat_pos"]
    rx = np.broadcast_to(ref, (t.size, 3))
    el = fidelity.elevations(sat, ref)
    lat, lon, h = pymap3d.ecef2geodetic(*ref, deg=False)
    rho, los = ranges_and_lines_of_sight(rx, sat)    # with the Sagnac term
    gd = real["group_delay"] if real.get("group_delay") is not None else np.zeros((len(real["sat_id"]), len(signals)))
    system = np.array([s[0] for s in real["sat_id"]])
    y = np.full(el.shape, np.nan)
    noise_var = np.full(el.shape, np.nan)
    pairs = {}
    obs = real["obs"]
    for letter in SYSTEMS:
        pair = dual_frequency_pair(signals, freq, letter)
        cols = system == letter
        if pair is None or not cols.any():
            continue
        i, j = pair
        fa, fb = freq[i] ** 2, freq[j] ** 2
        p_if = (fa * obs["code"][signals[i]] - fb * obs["code"][signals[j]]) / (fa - fb)
        gd_if = (fa * gd[:, i] - fb * gd[:, j]) / (fa - fb)
        l_if = (fa * obs["carrier"][signals[i]] * C_LIGHT / freq[i]
                - fb * obs["carrier"][signals[j]] * C_LIGHT / freq[j]) / (fa - fb)
        lli = obs["lli"][signals[i]].astype(np.uint8) | obs["lli"][signals[j]].astype(np.uint8)
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(p_if) & np.isfinite(el) & (el >= np.radians(elevation_cut_deg)) & cols[None, :]
        label = fidelity.arcs(ok & np.isfinite(l_if), lli, t)   # slips: the receiver's loss-of-lock flags, gaps
        levelled = level_to_carrier(l_if, p_if - l_if, label)
        code = np.where(label >= 0, levelled, p_if)
        r = code - gd_if[None, :] + C_LIGHT * real["sat_clock"] - rho - atmosphere.troposphere(lat, h, el)
        y[ok] = r[ok]
        noise_var[ok] = _arc_mean_variance(p_if - l_if, label, ok)[ok]
        pairs[letter] = [signals[i], signals[j]]
    unit = _units(np.isfinite(y), t, real["start"], system)
    utc = gpstime.gps_to_utc(*real["start"])
    doy = utc.timetuple().tm_yday + (utc.hour * 3600 + utc.minute * 60 + utc.second) / 86400.0
    return {"y": y, "noise_var": noise_var, "unit": unit, "el": el, "system": system, "lat": lat, "h": h, "los": los,
            "sat_pos": sat,
            "doy": doy, "pairs": pairs, "t": t, "sat_id": list(real["sat_id"])}


def _arc_mean_variance(mp, label, ok) -> np.ndarray:
    """Per epoch, the variance (m^2) of the mean of the code-minus-carrier ``mp`` over its arc: s^2 / n inflated by
    (1 + rho) / (1 - rho) for the pooled lag-one correlation rho; epochs outside a carrier arc (code alone) get
    the pooled scatter s^2 itself (no averaging claimed)."""
    out = np.full(mp.shape, np.nan)
    lab = label.ravel(order="F")
    x = mp.ravel(order="F")
    good = lab >= 0
    if not good.any():
        pooled = np.nan
        out[ok] = pooled
        return out
    ids, inv, n = np.unique(lab[good], return_inverse=True, return_counts=True)
    mean = np.bincount(inv, weights=x[good]) / n
    dev = x[good] - mean[inv]
    ss = np.bincount(inv, weights=dev ** 2)
    s2 = np.where(n > 1, ss / np.maximum(n - 1, 1), np.nan)
    pooled = float(np.sum(ss) / max(np.sum(n - 1), 1))
    s2 = np.where(np.isfinite(s2), s2, pooled)
    same = inv[1:] == inv[:-1]          # consecutive values of one arc
    num = float(np.sum(dev[:-1][same] * dev[1:][same]))
    rho = float(np.clip(num / np.sum(dev ** 2), 0.0, 0.95)) if np.sum(dev ** 2) > 0 else 0.0
    var = s2 / n * (1.0 + rho) / (1.0 - rho)
    flat = out.ravel(order="F")
    flat[np.flatnonzero(good)] = var[inv]
    out = flat.reshape(mp.shape, order="F")
    out[ok & ~(label >= 0)] = pooled
    return out


def _units(valid, t, start, system) -> np.ndarray:
    """Pass labels (M, S) int (-1 where not valid): a new pass at a gap of more than 1.5 intervals or where the
    satellite's ephemeris interval (the truth model's default ``*_ephemeris_interval_s`` of GPS time) changes."""
    week, sow = gpstime.add_seconds(*start, t)
    t_abs = np.asarray(week, float) * gpstime.SECONDS_PER_WEEK + np.asarray(sow, float)
    d = realistic_defaults()   # the truth model's ephemeris intervals (GPS 2 h, BDS 1 h uploads)
    period = np.array([d.get(f"{SYSTEMS.get(s, 'gps')}_ephemeris_interval_s", 7200.0) for s in system])
    block = np.floor(t_abs[:, None] / period[None, :] + 0.5)     # the nearest-toe record, as the truth model
    m, s = valid.shape
    dt = np.diff(t)
    interval = float(np.median(dt)) if dt.size else 1.0
    gap = np.concatenate([[True], dt > 1.5 * interval])
    new_block = np.concatenate([np.ones((1, s), bool), block[1:] != block[:-1]])
    prev = np.concatenate([np.zeros((1, s), bool), valid[:-1]])
    start_pass = valid & (~prev | gap[:, None] | new_block)
    label = np.cumsum(start_pass.ravel(order="F")).reshape((m, s), order="F") - 1
    return np.where(valid, label, -1)


def _unit_systems(unit, system) -> np.ndarray:
    """The system letter (U,) of each pass of ``unit`` (M, S) (-1: none), from the satellites' ``system`` (S,)."""
    ok = unit >= 0
    out = np.empty(int(unit.max()) + 1, dtype=system.dtype)
    out[unit[ok]] = np.broadcast_to(system, unit.shape)[ok]
    return out


def _two_way(values, unit, system, iterations: int = 500, tol: float = 1e-9):
    """Per-unit coefficients (U,) of ``values`` (M, S) = c_sys(t) + b_u by least squares (alternating means),
    centred per system (mean over units 0)."""
    n_unit = int(unit.max()) + 1
    ok = unit >= 0
    b = np.zeros(n_unit)
    unit_sys = _unit_systems(unit, system)
    counts = np.bincount(unit[ok], minlength=n_unit)
    for _ in range(iterations):
        resid = np.where(ok, values - np.where(ok, b[np.maximum(unit, 0)], 0.0), np.nan)
        clock = np.zeros(values.shape)
        for letter in np.unique(system):
            cols = system == letter
            n = ok[:, cols].sum(axis=1)
            c = np.where(ok[:, cols], resid[:, cols], 0.0).sum(axis=1) / np.maximum(n, 1)
            clock[:, cols] = c[:, None]
        new = np.bincount(unit[ok], weights=(values - clock)[ok], minlength=n_unit) / np.maximum(counts, 1)
        done = np.max(np.abs(new - b)) < tol
        b = new
        if done:
            break
    for letter in np.unique(unit_sys):
        b[unit_sys == letter] -= b[unit_sys == letter].mean()
    return b, unit_sys, counts


def fit(res: dict, position: bool = True) -> dict | None:
    """The SISRE per system and the zenith troposphere error from :func:`residuals` (module doc); None when fewer
    than ``MIN_UNITS`` passes of ``MIN_EPOCHS`` epochs. ``position``: estimate an offset of the reference (3
    unknowns, ECEF) with them, so that a reference wrong by a metre does not pass for orbit error (the part of
    the orbit errors that a position absorbs leaves the SISRE's degrees of freedom)."""
    y, el, system = res["y"], res["el"], res["system"]
    raw = np.where(np.isfinite(y), res["unit"], -1)
    if not (raw >= 0).any():
        return None
    counts = np.bincount(raw[raw >= 0])
    keep = (raw >= 0) & (counts[np.maximum(raw, 0)] >= MIN_EPOCHS)
    unit = np.full(y.shape, -1)
    if keep.any():
        unit[keep] = np.unique(raw[keep], return_inverse=True)[1]
    n_unit = int(unit.max()) + 1
    if n_unit < MIN_UNITS:
        return None
    elev = np.where(unit >= 0, el, np.pi / 2)
    m_h, m_w = niell_mapping(res["lat"], res["h"], elev, res["doy"])
    zh, zw = atmosphere.saastamoinen_zenith(res["lat"], res["h"])
    hypotheses = {"model": (np.zeros(y.shape), 1.0 / np.sin(elev)),
                  "niell": (zh * (m_h - 1.0 / np.sin(elev)) + zw * (m_w - 1.0 / np.sin(elev)), 0.5 * (m_h + m_w))}
    ok = unit >= 0
    noise = np.bincount(unit[ok], weights=res["noise_var"][ok], minlength=n_unit) / np.bincount(unit[ok])
    radius = np.linalg.norm(res["sat_pos"], axis=-1) if res.get("sat_pos") is not None else None
    unit_sys0 = _unit_systems(unit, system)
    unit_class = unit_sys0.astype(object)
    if radius is not None:   # BDS geosynchronous passes (GEO, IGSO): their own SISRE class
        r_unit = np.bincount(unit[ok], weights=np.nan_to_num(radius[ok])) / np.bincount(unit[ok])
        unit_class = np.where((unit_sys0 == "C") & (r_unit > GEOSYNC_RADIUS_M), "C_geo", unit_class)
    out = {}
    for name, (shift, mapping) in hypotheses.items():
        b, unit_sys, _ = _two_way(np.where(ok, y - shift, np.nan), unit, system)
        x, *_ = _two_way(np.where(ok, mapping, np.nan), unit, system)
        pos = [(_two_way(np.where(ok, -res["los"][..., i], np.nan), unit, system)[0]) for i in range(3)] \
            if position else []
        out[name] = _random_bias_fit(b, x, unit_sys, noise, pos, unit_class)
    decided = abs(out["model"]["minus2_log_l"] - out["niell"]["minus2_log_l"]) > LIKELIHOOD_MARGIN
    best = min(out, key=lambda k: out[k]["minus2_log_l"])
    chosen = out[best]
    return {"tropo_mapping": best if decided else None, "tropo_mapping_preferred": best,
            "hypotheses": {k: {kk: vv for kk, vv in v.items() if kk != "systems"} for k, v in out.items()},
            "zenith_delay_error_m": chosen["zenith_delay_error_m"],
            "zenith_delay_error_sigma_m": chosen["zenith_delay_error_sigma_m"],
            "systems": {k: {**v, "signals": res["pairs"].get(k[0])} for k, v in chosen["systems"].items()},
            "passes": n_unit}


def _random_bias_fit(b, x, unit_sys, noise, extra=(), unit_class=None, iterations: int = 30) -> dict:
    """b_u = a_sys + dT_z x_u + r_u, r_u ~ N(0, s_sys^2 + noise_u): weighted least squares for (a, dT_z) and, per
    system, the between-pass variance s_sys^2 by the method of moments (sum r^2 / (s^2 + noise) = dof, Paule and
    Mandel 1982), alternated; -2 log-likelihood for comparing the mapping hypotheses."""
    letters = sorted(set(unit_sys))
    a = np.column_stack([(unit_sys == s).astype(float) for s in letters] + list(extra) + [x])
    shared = len(extra) + 1          # parameters common to the systems (position, zenith delay)
    noise = np.where(np.isfinite(noise), noise, 0.0)
    unit_class = unit_sys if unit_class is None else np.asarray(unit_class)
    classes = sorted(set(unit_class))
    n_in_sys = {k: int(np.sum(unit_sys == k)) for k in letters}

    def dof_of(sel):   # the class's share of its system's intercept and of the shared parameters
        n = sel.sum()
        return n - n / n_in_sys[unit_sys[sel][0]] - shared * n / b.size

    s2 = {k: 0.25 for k in classes}
    for _ in range(iterations):
        var = np.array([s2[k] for k in unit_class]) + noise
        w = 1.0 / var
        normal = a.T @ (w[:, None] * a)
        coef = np.linalg.solve(normal, a.T @ (w * b))
        r = b - a @ coef
        for k in classes:
            sel = unit_class == k
            dof = dof_of(sel)
            if dof >= 1:
                s2[k] = _moment_variance(r[sel], noise[sel], dof)
    var = np.array([s2[k] for k in unit_class]) + noise
    cov = np.linalg.inv(a.T @ (a / var[:, None]))
    systems = {}
    for k in classes:
        sel = unit_class == k
        dof = dof_of(sel)
        if dof < 1:
            continue
        sig = float(np.sqrt(s2[k]))
        total = s2[k] + float(np.mean(noise[sel]))
        # sampling of a variance from dof residuals (chi-square), carried to the standard deviation
        unc = total / (max(sig, 1e-3) * np.sqrt(2.0 * dof))
        systems[k] = {"sisre_m": sig, "sisre_sigma_m": float(min(unc, np.sqrt(total))), "passes": int(sel.sum()),
                      "residual_rms_m": float(np.sqrt(np.mean(r[sel] ** 2))),
                      "arc_mean_noise_m": float(np.sqrt(np.mean(noise[sel])))}
    n_sys = len(letters)
    return {"zenith_delay_error_m": float(coef[-1]), "zenith_delay_error_sigma_m": float(np.sqrt(cov[-1, -1])),
            "position_offset_ecef_m": [float(v) for v in coef[n_sys:n_sys + len(extra)]],
            "position_offset_sigma_m": [float(np.sqrt(cov[i, i])) for i in range(n_sys, n_sys + len(extra))],
            "minus2_log_l": float(np.sum(np.log(var) + r ** 2 / var)), "systems": systems}


def _moment_variance(r, noise, dof) -> float:
    """The s^2 >= 0 with sum r^2 / (s^2 + noise) = dof (0 when even s^2 = 0 leaves the sum below dof)."""
    def excess(s2):
        return float(np.sum(r ** 2 / (s2 + noise + 1e-12))) - dof

    if excess(0.0) <= 0:
        return 0.0
    lo, hi = 0.0, float(np.sum(r ** 2)) + 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if excess(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


def parameters(result: dict | None, span_s: float) -> tuple[dict, list]:
    """The [gnss.truth_errors] keys the fit determines ({key: value}) and notes on the ones it leaves."""
    d = realistic_defaults()
    keys, notes = {}, []
    if result is None:
        return keys, ["too few dual-frequency GPS/BDS passes for the SISRE and troposphere fit: defaults kept"]
    if result["tropo_mapping"] is not None:
        keys["tropo_mapping"] = result["tropo_mapping"]
    else:
        notes.append(f"troposphere mapping not decided by the data (-2 log L of model / niell: "
                     f"{result['hypotheses']['model']['minus2_log_l']:.1f} / "
                     f"{result['hypotheses']['niell']['minus2_log_l']:.1f}): default kept")
    dz, sz = result["zenith_delay_error_m"], result["zenith_delay_error_sigma_m"]
    if abs(dz) > 2.0 * sz:
        h, w = d["tropo_zhd_sigma_m"], d["tropo_zwd_sigma_m"]
        k = abs(dz) / np.hypot(h, w)
        keys["tropo_zhd_sigma_m"], keys["tropo_zwd_sigma_m"] = float(min(h * k, 1.0)), float(min(w * k, 1.0))
    else:
        notes.append(f"zenith troposphere error {dz:+.3f} +- {sz:.3f} m: not distinguishable from 0 at 2 sigma, "
                     "tropo_zhd_sigma_m / tropo_zwd_sigma_m kept at the defaults")
    notes.append(f"tropo_zwd_random_walk_m_per_sqrt_h not identifiable from {span_s / 60:.0f} min of data: default kept")
    for letter, name in SYSTEMS.items():
        s = result["systems"].get(letter)
        if s is None:
            notes.append(f"{name.upper()}: no SISRE fit (too few dual-frequency passes): orbit and clock defaults kept")
            continue
        default = sisre_of(d[f"{name}_orbit_sigma_rac_m"], d[f"{name}_clock_sigma_m"], letter)
        k = s["sisre_m"] / default
        keys[f"{name}_orbit_sigma_rac_m"] = [float(v * k) for v in d[f"{name}_orbit_sigma_rac_m"]]
        keys[f"{name}_clock_sigma_m"] = float(d[f"{name}_clock_sigma_m"] * k)
    geo, meo = result["systems"].get("C_geo"), result["systems"].get("C")
    if geo is not None and meo is not None and meo["sisre_m"] > 0:
        keys["bds_geo_igso_sigma_scale"] = float(np.clip(geo["sisre_m"] / meo["sisre_m"], 0.0, 20.0))
    notes.append("the ephemeris intervals (*_ephemeris_interval_s) are not fitted: the systems' upload intervals")
    return keys, notes


def report_lines(result: dict | None) -> list[str]:
    """The report.md section of :func:`fit` (none without a fit)."""
    if not result:
        return []
    out = ["", "## Broadcast orbit/clock (SISRE) and troposphere", "",
           "Ionosphere-free code residuals at the reference, one receiver clock per system and epoch removed, the "
           "per-pass biases against the zenith delay error (docs/real_data.md).", "",
           "| system | signals | passes | SISRE (m) | +- (m) | residual RMS (m) | arc-mean noise (m) | default SISRE (m) |",
           "|---|---|---:|---:|---:|---:|---:|---:|"]
    d = realistic_defaults()
    for key, s in result["systems"].items():
        name = SYSTEMS[key[0]]
        default = sisre_of(d[f"{name}_orbit_sigma_rac_m"], d[f"{name}_clock_sigma_m"], key[0])
        out.append(f"| {CLASS_NAMES[key]} | {'+'.join(s['signals'] or [])} | {s['passes']} | {s['sisre_m']:.2f} | "
                   f"{s['sisre_sigma_m']:.2f} | {s['residual_rms_m']:.2f} | {s['arc_mean_noise_m']:.2f} | {default:.2f} |")
    out += ["", "| mapping hypothesis | zenith delay error (m) | +- (m) | -2 log L |", "|---|---:|---:|---:|"]
    for k, h in result["hypotheses"].items():
        out.append(f"| {k} | {h['zenith_delay_error_m']:+.3f} | {h['zenith_delay_error_sigma_m']:.3f} | "
                   f"{h['minus2_log_l']:.1f} |")
    chosen = result["hypotheses"][result["tropo_mapping_preferred"]]
    out += ["", f"Mapping decided by the data: {result['tropo_mapping'] or 'no (default kept)'}. Reference offset "
            "estimated with them (ECEF, m): " + ", ".join(f"{v:+.2f} +- {e:.2f}" for v, e in
                                                          zip(chosen["position_offset_ecef_m"],
                                                              chosen["position_offset_sigma_m"])) + "."]
    return out
