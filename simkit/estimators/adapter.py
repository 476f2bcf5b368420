"""The file adapter of the estimators: GNSS fixes, IMU samples, attitude fixes, the DD carrier and the filter's
noise model read from an open simkit file (:func:`simkit.open`) through the typed readers of :mod:`simkit.io`.

Units SI; positions ECEF, velocities ENU at the position, lever arms in the body frame (x right, y forward, z up).
"""
from __future__ import annotations

import json

import numpy as np

from .. import attitude as gnss_attitude
from ..gnss.differencing import systems_of
from ..gnss.spp import SppFixes, spp
from ..io import broadcast_ionosphere as file_ionosphere
from ..constellation import time_offsets
from ..io import broadcast_time_offsets, has, n_antennas, read_gnss, read_imu
from .errors import EstimatorInputError
from .filters import FilterConfig
from .inputs import AttitudeFixes, DDCarrier, GnssFixes, ImuData
from .truth_inputs import truth_attitude, truth_fixes


def antenna(ds, p) -> int:
    """The antenna index ``p['antenna']``, checked against the file's antennas."""
    a = int(p["antenna"])
    n_ant = n_antennas(ds)
    if not 0 <= a < n_ant:
        raise EstimatorInputError(f"estimator.antenna: expected 0 .. {n_ant - 1}, got {a}")
    return a


def broadcast_ionosphere(ds, p):
    """(``{system: (alpha, beta)}`` or None, why): the file's broadcast Klobuchar coefficients when
    ``p['ionosphere']`` is "broadcast" and the file has them (files written before /gnss/iono_alpha existed
    have not: no correction, and the reason says so)."""
    if p["ionosphere"] == "none":
        return None, "none (estimator.ionosphere = none)"
    coef = file_ionosphere(ds)
    if coef is None:
        return None, f"none ({ds.path} has no /gnss/iono_alpha: written before simkit stored the broadcast model)"
    return coef, "broadcast Klobuchar (" + ", ".join(sorted(coef)) + ") from /gnss/iono_alpha, /gnss/iono_beta"


def spp_fixes(ds, p):
    """Single-point fixes of antenna ``p['antenna']`` from /gnss/obs (first tracked signal per satellite, or the
    ionosphere-free combination of its first two signals with ``p['ionosphere'] = 'iono-free'``) of the systems
    ``p['systems']`` (every system of the file when empty)."""
    g = read_gnss(ds, antennas=antenna(ds, p), obs=("code", "doppler"))
    code = doppler = None
    for j, sig in enumerate(g.signals):
        c, d = g.obs["code"][sig], g.obs["doppler"][sig]
        if code is None:
            code, doppler = c.copy(), d.copy()
            wl, gd = g.sat_wavelength_m[:, j].copy(), g.group_delay[:, j].copy()  # per satellite: FDMA
        take = np.isnan(code).all(0) & ~np.isnan(c).all(0)
        code[:, take], doppler[:, take], wl[take], gd[take] = c[:, take], d[:, take], g.sat_wavelength_m[take, j], \
            g.group_delay[take, j]
    if p["ionosphere"] == "iono-free":
        code, gd, iono, why = ionosphere_free(g)
    else:
        iono, why = broadcast_ionosphere(ds, p)
    if p["systems"]:
        code = np.where(np.isin(systems_of(g.sat_id), list(p["systems"]))[None, :], code, np.nan)
    sow = float(ds.attrs["start_gps_sow"]) + g.t
    offset = None
    if p["clock"] == "single":  # one receiver clock: the satellites' clocks are moved to GPS time first
        offset = time_offsets.evaluate(broadcast_time_offsets(ds), systems_of(g.sat_id),
                                       int(ds.attrs["start_gps_week"]), sow)[0]
    fx = spp(g.t, code, doppler, wl, g.sat_pos_ecef, g.sat_clock, systems_of(g.sat_id), gd,
             p["elevation_mask_deg"], p["sigma_code_m"], p["sigma_doppler_m_per_s"], iono_coefficients=iono,
             gps_sow=sow, time_offset_s=offset, single_clock=p["clock"] == "single")
    return SppFixes(**{**fx.__dict__, "ionosphere": why})


def ionosphere_free(g):
    """Ionosphere-free code (M, S) m of each satellite's first two signals of different frequencies (file order),
    P_IF = (f1^2 P1 - f2^2 P2) / (f1^2 - f2^2), and its group delay (S,) m by the same combination (0 for GPS
    L1/L2 T_GD, whose clock is the L1/L2 combination's); NaN where a satellite has one frequency at an epoch.
    Returns (code, group delay, None, description)."""
    m, s = next(iter(g.obs["code"].values())).shape
    systems = systems_of(g.sat_id)
    freq = 299792458.0 / np.asarray(g.wavelength_m, float)
    code, gd = np.full((m, s), np.nan), np.zeros(s)
    pairs = []
    for sys in sorted(set(systems)):
        cols = systems == sys
        have = [j for j, sig in enumerate(g.signals) if np.isfinite(g.obs["code"][sig][:, cols]).any()]
        pair = next(((a, b) for i, a in enumerate(have) for b in have[i + 1:] if freq[a] != freq[b]), None)
        if pair is None:
            continue
        a, b = pair
        fa, fb = freq[a] ** 2, freq[b] ** 2
        pa, pb = g.obs["code"][g.signals[a]][:, cols], g.obs["code"][g.signals[b]][:, cols]
        code[:, cols] = (fa * pa - fb * pb) / (fa - fb)
        gd[cols] = (fa * g.group_delay[cols, a] - fb * g.group_delay[cols, b]) / (fa - fb)
        pairs.append(f"{g.signals[a]}+{g.signals[b]}")
    if not pairs:
        raise EstimatorInputError("estimator.ionosphere: iono-free needs code on two frequencies of one system; "
                                  f"the file has {', '.join(g.signals)}")
    return code, gd, None, "ionosphere-free code (" + ", ".join(pairs) + ")"


def gnss_fixes(ds, p) -> GnssFixes:
    """The GNSS position/velocity fixes of ``p['gnss']`` ("spp", or "truth": a study input) at antenna
    ``p['antenna']``, with its lever arm plus ``p['lever_arm_error_m']``."""
    a = antenna(ds, p)
    lever = read_gnss(ds, antennas=a, epochs=slice(0, 0), satellites=False).lever_arm_b
    if p["gnss"] == "truth":
        t, pos, vel, cp, cv = truth_fixes(ds, p, a)
    elif p["gnss"] == "spp":
        fx = spp_fixes(ds, p)
        t, pos, vel, cp, cv = fx.t, fx.pos_ecef, fx.vel_enu, fx.pos_cov_enu, fx.vel_cov_enu
    else:
        raise EstimatorInputError(f"estimator.gnss: expected 'spp' or 'truth', got {p['gnss']!r}")
    return GnssFixes(t, pos, vel, cp * float(p["pos_sigma_scale"]) ** 2, cv, lever + np.asarray(
        p.get("lever_arm_error_m", [0.0, 0.0, 0.0]), float))


def imu_data(ds) -> ImuData:
    """The file's IMU samples: angle/velocity increments when it holds them, else rates and specific forces."""
    # increments first: an increments file also holds /imu/gyro = dtheta / dt, the interval mean, which taken
    # as a rate sample at t[k] lags half an interval
    if has(ds, "imu", "dtheta"):
        imu = read_imu(ds, fields=("dtheta", "dvel"))
        return ImuData(imu.t, imu.dtheta, imu.dvel, increments=True)
    if has(ds, "imu", "gyro"):
        imu = read_imu(ds, fields=("gyro", "accel"))
        return ImuData(imu.t, imu.gyro, imu.accel)
    raise EstimatorInputError(f"{ds.path}: no /imu/gyro or /imu/dtheta: the file has no IMU data")


def imu_model(ds) -> dict:
    """The simulated IMU's white noise, turn-on bias and rate random walk per sensor (SI), from /imu attrs."""
    attrs = ds.group_attrs("imu")
    out = {}
    for sensor in ("gyro", "accel"):
        m = json.loads(attrs[sensor]) if sensor in attrs else {}
        out[sensor] = (m.get("random_walk", 0.0), m.get("bias_turn_on", 0.0), m.get("rate_random_walk", 0.0),
                       m.get("bias_instability", 0.0))
    return out


BIAS_MEMORY_S = 100.0  # the bias instability enters as the random walk that reaches its Allan floor at this tau


def bias_walk(rate_random_walk: float, bias_instability: float) -> float:
    """Bias random-walk density (unit/sqrt(s)) for the filter: the sensor's rate random walk K plus its bias
    instability B (IEEE coefficient, flicker) as the random walk whose Allan deviation K' sqrt(tau/3) equals the
    flicker floor 0.664 B at tau = BIAS_MEMORY_S. A filter with no process noise on its bias states trusts its
    bias estimate more every hour while a flicker bias keeps wandering: on the 3 h static site kf21's height
    error was 2.8 m RMS (SPP fixes: 1.3 m) and 23 % of its NEES inside the bounds; with this term 0.66 m, 88 %."""
    return float(np.hypot(rate_random_walk, 0.664 * bias_instability * np.sqrt(3.0 / BIAS_MEMORY_S)))


# The slowly varying error of broadcast SPP fixes (E, N, U, m, 1 sigma) and its correlation time: orbit and clock
# errors (SISRE 0.5-1 m), ionosphere (half of Klobuchar's delay) and troposphere residuals through HDOP ~1, VDOP ~2.
# Measured on simkit's realistic truth errors (xian_static_bds, 2 h, GPS+BDS: the 60 s mean of the SPP error has
# RMS 0.9, 0.9, 1.9 m and decorrelates over 300-900 s) and in line with a broadcast SPP's 2-5 m (95 %).
# (Not in the H-infinity filter's defaults: simkit.estimators.registry.)
SPP_ERROR_SIGMA_M = (1.5, 1.5, 3.0)


def filter_config(ds, p, name) -> FilterConfig:
    """The filter's noise model and initial uncertainty: ``p`` where given, else the file's IMU model."""
    m = imu_model(ds)
    pick = lambda key, default: float(p[key]) if p[key] is not None else float(default)  # noqa: E731
    return FilterConfig(
        gyro_arw=pick("gyro_arw", max(m["gyro"][0], 1e-7)), accel_vrw=pick("accel_vrw", max(m["accel"][0], 1e-6)),
        gyro_bias_rw=pick("gyro_bias_rw", bias_walk(m["gyro"][2], m["gyro"][3])),
        accel_bias_rw=pick("accel_bias_rw", bias_walk(m["accel"][2], m["accel"][3])),
        p0_gyro_bias=pick("p0_gyro_bias", max(m["gyro"][1] + m["gyro"][3], 1e-7)),
        p0_accel_bias=pick("p0_accel_bias", max(m["accel"][1] + m["accel"][3], 1e-5)),
        p0_att=tuple(np.radians(np.broadcast_to(np.asarray(p["p0_att_deg"], float), 3))),
        p0_vel=float(p["p0_vel_m_per_s"]), p0_pos=tuple(np.broadcast_to(np.asarray(p["p0_pos_m"], float), 3)),
        p0_lever=float(p.get("p0_lever_m", FilterConfig.p0_lever)), cov_dt=float(p["cov_dt_s"]),
        alpha=float(p.get("alpha", 10.0)),
        lever_rate_window_s=float(p.get("lever_rate_window_s", FilterConfig.lever_rate_window_s)),
        gamma_rule=str(p.get("gamma_rule", "wu")), dd_gate_p=float(p.get("dd_gate_p", 0.0)),
        # "static", "motion" and "attitude" take the initial position (and attitude) from the fixes of the initial
        # epoch: only "truth" leaves them independent, to be used as measurements
        update_at_start=p.get("align") == "truth",
        gnss_error_sigma=tuple(np.broadcast_to(np.asarray(
            p["gnss_error_sigma_m"] if p["gnss_error_sigma_m"] is not None
            else (SPP_ERROR_SIGMA_M if p["gnss"] == "spp" else 0.0), float), 3)),
        gnss_error_tau=float(p["gnss_error_tau_s"]))


def solved_attitude(ds, p, solver_params: dict | None = None) -> AttitudeFixes:
    """GNSS attitude from the multi-antenna carrier-phase solver ``p['attitude_method']`` of simkit.attitude
    (its defaults overridden by ``solver_params``): its Euler angles and their covariance at the epochs whose
    ambiguities are fixed and validated (status fixed, or wrong fix: the filter cannot tell them apart)."""
    sol = gnss_attitude.SOLVERS[p["attitude_method"]](ds, solver_params or {})
    ok = np.isin(sol.extras["status"], (1, 3)) & np.isfinite(sol.euler).all(1) & np.isfinite(sol.cov).all((1, 2))
    return AttitudeFixes(sol.t[ok], sol.euler[ok], sol.cov[ok])


def attitude_fixes(ds, p, source: str) -> AttitudeFixes | None:
    """GNSS attitude for the 21-state filter from the resolved ``source``: the attitude solver ("attitude"),
    none ("none"), or the truth plus white noise ("truth": a study input, :func:`truth_attitude`)."""
    if source == "none":
        return None
    if source == "attitude":
        return solved_attitude(ds, p)
    return truth_attitude(ds, p)


def dd_carrier(ds, p) -> DDCarrier:
    """The fixed DD carrier of every baseline from ``simkit.attitude`` (``dd_method``, ``dd_signals``,
    ``dd_mask_deg``, ``dd_ratio_threshold``; the other ambiguity parameters at their defaults)."""
    n_ant = n_antennas(ds)
    if n_ant < 2:
        raise EstimatorInputError(f"{ds.path}: kf15_dd needs 2 or more antennas (one baseline), the file has {n_ant}")
    window = float(p["dd_correlation_window_s"])
    if window > 0:  # in samples of the GNSS interval
        t = read_gnss(ds, epochs=slice(0, 2), satellites=False).t
        window = window / float(t[1] - t[0]) if t.size > 1 else 1.0
    fx = gnss_attitude.read_fixed_dd(ds, {"signals": p["dd_signals"], "mask_deg": p["dd_mask_deg"],
                                          "ratio_threshold": p["dd_ratio_threshold"]}, p["dd_method"],
                                     float(p["dd_correlation_s"]), window if window > 0 else np.inf)
    return DDCarrier(fx.t, fx.offsets, fx.los_enu, fx.baseline_b, fx.range_m, fx.cov)
