"""``simkit solve`` entries: ``SOLVERS[name](ds, params, progress) -> Solution`` for spp, kf15, kf15_dd, kf21, hinf.

``params`` are ``--set estimator.key=value`` overrides over ``DEFAULTS`` (an unknown key is an error naming it).
Noise defaults come from the file's ``/imu`` model attributes (white noise, turn-on bias, rate random walk), so
a filter run on simulated data is tuned to the simulated IMU unless told otherwise.
"""
from __future__ import annotations

import json

import numpy as np

from .. import attitude as gnss_attitude
from ..frames import ecef_to_lla, enu_to_ecef_vec, ecef_to_enu_vec, quat_from_euler
from ..params import merge
from ..solution import Solution, warn_truth
from .align import motion_alignment, static_alignment
from .errors import EstimatorInputError
from .filters import FilterConfig, HInfinityFilter, KalmanFilter15, KalmanFilter15DD, KalmanFilter21
from .inputs import AttitudeFixes, DDCarrier, GnssFixes, ImuData, InitialState
from .spp import SppFixes, spp

COMMON = {"gnss": "spp", "antenna": 0, "elevation_mask_deg": 10.0, "sigma_code_m": 1.0,
          "sigma_doppler_m_per_s": 0.04, "ionosphere": "broadcast", "truth_pos_sigma_m": [1.0, 1.0, 5.0], "truth_vel_sigma_m_per_s": 0.05,
          "seed": 0}
FILTER = {"align": "auto", "align_static_s": 10.0, "init_heading_error_deg": 0.0, "p0_att_deg": [1.0, 1.0, 10.0],
          "p0_vel_m_per_s": 0.5, "p0_pos_m": [5.0, 5.0, 10.0], "gyro_arw": None, "accel_vrw": None,
          "gyro_bias_rw": None, "accel_bias_rw": None, "p0_gyro_bias": None, "p0_accel_bias": None,
          "cov_dt_s": 0.1, "pos_sigma_scale": 1.0}
DEFAULTS = {"spp": dict(COMMON), "kf15": {**COMMON, **FILTER},
            "hinf": {**COMMON, **FILTER, "alpha": 10.0, "gamma_rule": "wu"},
            "kf21": {**COMMON, **FILTER, "use_attitude": True, "attitude_sigma_deg": 0.3, "p0_lever_m": 0.1,
                     "lever_rate_window_s": 0.1,
                     "lever_arm_error_m": [0.0, 0.0, 0.0], "attitude_source": "auto", "attitude_method": "attitude"},
            # the fixed DD carrier: ambiguity method, signals, elevation mask and ratio threshold of simkit.attitude
            "kf15_dd": {**COMMON, **FILTER,
                        "dd_method": "lambda", "dd_signals": "all", "dd_mask_deg": 10.0,
                        "dd_ratio_threshold": 3.0, "dd_gate_p": 1e-6, "dd_correlation_s": 0.0,
                        "dd_correlation_window_s": 0.0}}
def merged(name: str, params: dict) -> dict:
    """Defaults of filter ``name`` overridden by ``params``, checked against :data:`simkit.params.SCHEMA`
    (types, ranges, choices); an unknown key or a bad value raises naming ``estimator.<key>``."""
    return merge(DEFAULTS[name], params, name, lambda key, message: EstimatorInputError(f"{key}: {message}"))


def _system_of(sat_ids):
    return np.array([s[0] for s in sat_ids])


def _antenna(ds, p) -> int:
    a = int(p["antenna"])
    n_ant = ds["gnss/antennas/lever_arm_b"].shape[0]
    if not 0 <= a < n_ant:
        raise EstimatorInputError(f"estimator.antenna: expected 0 .. {n_ant - 1}, got {a}")
    return a


def broadcast_ionosphere(ds, p):
    """(``{system: (alpha, beta)}`` or None, why): the file's broadcast Klobuchar coefficients when
    ``p['ionosphere']`` is "broadcast" and the file has them (files written before /gnss/iono_alpha existed
    have not: no correction, and the reason says so)."""
    if p["ionosphere"] == "none":
        return None, "none (estimator.ionosphere = none)"
    if "gnss/iono_alpha" not in ds:
        return None, f"none ({ds.path} has no /gnss/iono_alpha: written before simkit stored the broadcast model)"
    systems = [str(x) for x in ds["gnss/iono_systems"][:]]  # the reader returns str
    alpha, beta = ds["gnss/iono_alpha"][:], ds["gnss/iono_beta"][:]
    coef = {k: (alpha[i], beta[i]) for i, k in enumerate(systems)}
    return coef, "broadcast Klobuchar (" + ", ".join(sorted(coef)) + ") from /gnss/iono_alpha, /gnss/iono_beta"


def spp_fixes(ds, p):
    """Single-point fixes of antenna ``p['antenna']`` from /gnss/obs (first tracked signal per satellite)."""
    sat_ids = ds["gnss/sat_id"][:]
    signals, lam = list(ds["gnss/signals"][:]), ds["gnss/wavelength_m"][:]
    gd_all = ds["gnss/group_delay"][:]
    a = _antenna(ds, p)
    code = doppler = None
    for j, sig in enumerate(signals):
        c = ds[f"gnss/obs/{sig}/code"][:, a, :]
        d = ds[f"gnss/obs/{sig}/doppler"][:, a, :]
        if code is None:
            code, doppler = c.copy(), d.copy()
            wl, gd = np.full(c.shape[1], lam[j]), gd_all[:, j].copy()
        take = np.isnan(code).all(0) & ~np.isnan(c).all(0)
        code[:, take], doppler[:, take], wl[take], gd[take] = c[:, take], d[:, take], lam[j], gd_all[take, j]
    iono, why = broadcast_ionosphere(ds, p)
    t = ds["gnss/t"][:]
    fx = spp(t, code, doppler, wl, ds["gnss/sat_pos_ecef"][:], ds["gnss/sat_clock"][:], _system_of(sat_ids), gd,
             p["elevation_mask_deg"], p["sigma_code_m"], p["sigma_doppler_m_per_s"], iono_coefficients=iono,
             gps_sow=float(ds.attrs["start_gps_sow"]) + t)
    return SppFixes(**{**fx.__dict__, "ionosphere": why})


def solve_spp(ds, params, progress=False) -> Solution:
    p = merged("spp", params)
    fx = spp_fixes(ds, p)
    cov = np.full((fx.t.size, 6, 6), np.nan)
    cov[:, :3, :3], cov[:, 3:, 3:] = fx.pos_cov_enu, fx.vel_cov_enu
    return Solution(t=fx.t, pos_ecef=fx.pos_ecef, vel_enu=fx.vel_enu, cov=cov, point=f"antenna:{int(p['antenna'])}",
                    state_names=("pos_e", "pos_n", "pos_u", "vel_e", "vel_n", "vel_u"),
                    extras={"clock": fx.clock, "n_sats": fx.n_sats},
                    extra_units={"clock": "m (one column per system: " + ",".join(fx.systems) + ")",
                                 "n_sats": "1"},
                    config={"estimator": "spp", "point": f"antenna {p['antenna']} phase centre",
                            "ionosphere_correction": fx.ionosphere, **p})


def _truth_fixes(ds, p):
    """Truth antenna position/velocity plus white noise of the given sigmas (a study input, not a receiver)."""
    a = int(p["antenna"])
    t = ds["gnss/t"][:]
    pos = ds["gnss/truth/antenna_pos_ecef"][:, a]
    lla = ecef_to_lla(pos)
    vel = ecef_to_enu_vec(ds["gnss/truth/antenna_vel_ecef"][:, a], lla[:, 0], lla[:, 1])
    rng = np.random.default_rng(int(p["seed"]))
    sp = np.broadcast_to(np.asarray(p["truth_pos_sigma_m"], float), 3)
    sv = float(p["truth_vel_sigma_m_per_s"])
    pos = pos + enu_to_ecef_vec(rng.normal(size=pos.shape) * sp, lla[:, 0], lla[:, 1])
    vel = vel + rng.normal(size=vel.shape) * sv
    cov_p = np.broadcast_to(np.diag(sp**2), (t.size, 3, 3))
    return t, pos, vel, cov_p, np.broadcast_to(np.eye(3) * sv**2, (t.size, 3, 3))


def gnss_fixes(ds, p) -> GnssFixes:
    lever = ds["gnss/antennas/lever_arm_b"][_antenna(ds, p)]
    if p["gnss"] == "truth":
        t, pos, vel, cp, cv = _truth_fixes(ds, p)
    elif p["gnss"] == "spp":
        fx = spp_fixes(ds, p)
        t, pos, vel, cp, cv = fx.t, fx.pos_ecef, fx.vel_enu, fx.pos_cov_enu, fx.vel_cov_enu
    else:
        raise EstimatorInputError(f"estimator.gnss: expected 'spp' or 'truth', got {p['gnss']!r}")
    return GnssFixes(t, pos, vel, cp * float(p["pos_sigma_scale"]) ** 2, cv, lever + np.asarray(
        p.get("lever_arm_error_m", [0.0, 0.0, 0.0]), float))


def imu_data(ds) -> ImuData:
    # increments first: an increments file also holds /imu/gyro = dtheta / dt, the interval mean, which taken
    # as a rate sample at t[k] lags half an interval
    if "imu/dtheta" in ds:
        return ImuData(ds["imu/t"][:], ds["imu/dtheta"][:], ds["imu/dvel"][:], increments=True)
    if "imu/gyro" in ds:
        return ImuData(ds["imu/t"][:], ds["imu/gyro"][:], ds["imu/accel"][:])
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


def filter_config(ds, p, name) -> FilterConfig:
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
        update_at_start=p.get("align") == "truth")


def _attitude_alignment(ds, p, gnss: GnssFixes, good, stop_s: float | None = None):
    """([pitch, roll, heading] rad, GNSS fix index): the first fixed epoch of the attitude solver (epochs up to
    ``stop_s`` s; None: all) that has a GNSS fix at the same time."""
    if ds["gnss/antennas/lever_arm_b"].shape[0] < 3:
        raise EstimatorInputError(f"estimator.align: 'attitude' needs 3 or more antennas, {ds.path} has "
                                  f"{ds['gnss/antennas/lever_arm_b'].shape[0]}")
    att = _solved_attitude(ds, {"attitude_method": p.get("attitude_method", "attitude")},
                           {} if stop_s is None else {"stop_s": float(stop_s)})
    both = np.flatnonzero(np.isin(np.round(gnss.t[good], 6), np.round(att.t, 6)))
    if both.size == 0:
        raise EstimatorInputError("estimator.align: 'attitude' found no epoch with fixed ambiguities and a GNSS fix")
    g0 = good[both[0]]
    return att.euler[np.argmin(np.abs(att.t - gnss.t[g0]))], g0


def initial_state(ds, p, imu: ImuData, gnss: GnssFixes, found=None) -> InitialState:
    """Initial navigation state from ``p['align']``: 'static' (levelling + gyrocompassing over the first
    align_static_s; at the first IMU sample), 'motion' (from the first GNSS fix faster than 5 m/s, at its epoch),
    'attitude' (the multi-antenna carrier-phase attitude at its first fixed epoch, 3+ antennas; at that GNSS
    fix; ``found`` an alignment :func:`resolve_align` already made), 'truth' (the file's truth at the first sample,
    a study mode), plus ``init_heading_error_deg``."""
    good = np.flatnonzero(np.isfinite(gnss.pos_ecef).all(1))
    if good.size == 0:
        raise EstimatorInputError(f"{ds.path}: no GNSS fix to initialise the position from")
    g0 = good[0]
    lla_ant = ecef_to_lla(gnss.pos_ecef[g0])
    if p["align"] == "truth":
        euler, lla, vel = ds["truth/euler"][0], ds["truth/pos_lla"][0], ds["truth/vel_enu"][0]
    elif p["align"] == "attitude":
        euler, g0 = found if found is not None else _attitude_alignment(ds, p, gnss, good)
        vel, lla = gnss.vel_enu[g0], ecef_to_lla(gnss.pos_ecef[g0])
    elif p["align"] in ("static", "motion"):
        if p["align"] == "static":
            n = max(2, int(np.searchsorted(imu.t, imu.t[0] + float(p["align_static_s"]))))
            rates = imu.gyro[:n] if not imu.increments else imu.gyro[1:n] / np.diff(imu.t[:n])[:, None]
            force = imu.accel[:n] if not imu.increments else imu.accel[1:n] / np.diff(imu.t[:n])[:, None]
            euler, _ = static_alignment(rates, force, lla_ant[0])
            vel = np.zeros(3)
        else:
            moving = good[np.hypot(gnss.vel_enu[good, 0], gnss.vel_enu[good, 1]) > MOTION_SPEED_M_S]
            if moving.size == 0:
                raise EstimatorInputError(f"estimator.align: 'motion' needs a GNSS speed above {MOTION_SPEED_M_S:g} "
                                          f"m/s, {ds.path} has none; try 'static' or 'auto'")
            g0 = moving[0]
            euler, vel = motion_alignment(gnss.vel_enu[g0]), gnss.vel_enu[g0]
            lla_ant = ecef_to_lla(gnss.pos_ecef[g0])
        lla = lla_ant  # the lever arm (metres) is left to the filter's position uncertainty
    else:
        raise EstimatorInputError(f"estimator.align: expected 'static', 'motion', 'truth' or 'attitude', "
                                  f"got {p['align']!r}")
    euler = np.asarray(euler, float) + [0.0, 0.0, np.radians(float(p["init_heading_error_deg"]))]
    t0 = float(gnss.t[g0]) if p["align"] in ("motion", "attitude") else float(imu.t[0])
    return InitialState(t0, np.asarray(lla, float), np.asarray(vel, float), quat_from_euler(*euler))


AUTO_ATTITUDE_S = 300.0   # align = "auto" looks for a fixed attitude in the first 300 s only
STATIC_SPEED_M_S = 0.5    # stationary start: every GNSS speed in the first align_static_s below this
STATIC_FORCE_STD = 0.1    # and the IMU specific-force magnitude steadier than this (m/s^2, sd)
MOTION_SPEED_M_S = 5.0    # "motion" alignment: the first GNSS fix with a horizontal speed above this


def stationary_start(p, imu: ImuData, gnss: GnssFixes) -> bool:
    """True when the first ``align_static_s`` look stationary: every GNSS velocity fix in it below
    STATIC_SPEED_M_S (at least 2 fixes) and the specific-force magnitude's sd below STATIC_FORCE_STD."""
    span = float(p["align_static_s"])
    g = np.flatnonzero((gnss.t <= imu.t[0] + span) & np.isfinite(gnss.vel_enu).all(1))
    n = max(2, int(np.searchsorted(imu.t, imu.t[0] + span)))
    force = imu.accel[:n] if not imu.increments else imu.accel[1:n] / np.diff(imu.t[:n])[:, None]
    return bool(g.size >= 2 and np.all(np.linalg.norm(gnss.vel_enu[g], axis=1) < STATIC_SPEED_M_S)
                and np.std(np.linalg.norm(force, axis=1)) < STATIC_FORCE_STD)


def resolve_align(ds, p, imu: ImuData, gnss: GnssFixes):
    """(``p['align']`` with "auto" resolved, the attitude alignment found or None): "attitude" when the file has
    3+ antennas and the attitude solver fixes an epoch with a GNSS fix in the first AUTO_ATTITUDE_S, else
    "static" when the start is stationary (:func:`stationary_start`), else "motion" when some GNSS fix is faster
    than MOTION_SPEED_M_S, else "static" (levelling is all that is left on a slow platform)."""
    if p["align"] != "auto":
        return p["align"], None
    good = np.flatnonzero(np.isfinite(gnss.pos_ecef).all(1))
    if ds["gnss/antennas/lever_arm_b"].shape[0] >= 3 and good.size:
        try:
            return "attitude", _attitude_alignment(ds, p, gnss, good, float(gnss.t[good[0]]) + AUTO_ATTITUDE_S)
        except EstimatorInputError:
            pass
    if stationary_start(p, imu, gnss):
        return "static", None
    fast = np.hypot(gnss.vel_enu[good, 0], gnss.vel_enu[good, 1]) > MOTION_SPEED_M_S
    return ("motion" if fast.any() else "static"), None


def attitude_source(ds, p) -> str:
    """``p['attitude_source']`` with "auto" resolved: "attitude" (simkit's own carrier-phase attitude) when the
    file has 3 or more antennas, else "none" (no attitude updates: a default never reads the truth);
    "attitude" with fewer than 3 antennas is an error naming the key."""
    n_ant = ds["gnss/antennas/lever_arm_b"].shape[0]
    src = p["attitude_source"]
    if src == "auto":
        return "attitude" if n_ant >= 3 else "none"
    if src == "attitude" and n_ant < 3:
        raise EstimatorInputError(f"estimator.attitude_source: 'attitude' needs 3 or more antennas (pitch, roll "
                                  f"and heading), {ds.path} has {n_ant}; use 'none' (or kf15_dd, whose DD "
                                  f"update takes one baseline)")
    return src


TRUTH_KEYS = {"gnss": "the true antenna position/velocity plus white noise as GNSS fixes",
              "align": "the true initial position, velocity and attitude",
              "attitude_source": "the true attitude plus white noise as GNSS attitude fixes"}


def truth_inputs(p, att_source: str | None = None) -> list:
    """The keys of ``p`` (with the resolved ``att_source``) whose value makes the filter read /truth; empty for
    every default. Each is an explicit study option, warned about and recorded in the solution config."""
    used = {"gnss": p.get("gnss"), "align": p.get("align"), "attitude_source": att_source}
    return [k for k in TRUTH_KEYS if used[k] == "truth"]


def _solved_attitude(ds, p, solver_params: dict | None = None) -> AttitudeFixes:
    """GNSS attitude from the multi-antenna carrier-phase solver ``p['attitude_method']`` of simkit.attitude
    (its defaults overridden by ``solver_params``): its Euler angles and their covariance at the epochs whose
    ambiguities are fixed and validated (status fixed, or wrong fix: the filter cannot tell them apart)."""
    sol = gnss_attitude.SOLVERS[p["attitude_method"]](ds, solver_params or {})
    ok = np.isin(sol.extras["status"], (1, 3)) & np.isfinite(sol.euler).all(1) & np.isfinite(sol.cov).all((1, 2))
    return AttitudeFixes(sol.t[ok], sol.euler[ok], sol.cov[ok])


def _attitude(ds, p, source: str) -> AttitudeFixes | None:
    """GNSS attitude for the 21-state filter from the resolved ``source``: the attitude solver ("attitude"),
    none ("none"), or the truth at the GNSS epochs plus white noise of attitude_sigma_deg ("truth": a study
    input)."""
    if source == "none":
        return None
    if source == "attitude":
        return _solved_attitude(ds, p)
    t = ds["gnss/t"][:]
    k = np.clip(np.searchsorted(ds["truth/t"][:], t), 0, ds["truth/t"].shape[0] - 1)
    sig = np.radians(float(p["attitude_sigma_deg"]))
    rng = np.random.default_rng(int(p["seed"]) + 1)
    return AttitudeFixes(t, ds["truth/euler"][:][k] + rng.normal(size=(t.size, 3)) * sig, np.full(3, sig))


def dd_carrier(ds, p) -> DDCarrier:
    """The fixed DD carrier of every baseline from ``simkit.attitude`` (``dd_method``, ``dd_signals``,
    ``dd_mask_deg``, ``dd_ratio_threshold``; the other ambiguity parameters at their defaults)."""
    n_ant = ds["gnss/antennas/lever_arm_b"].shape[0]
    if n_ant < 2:
        raise EstimatorInputError(f"{ds.path}: kf15_dd needs 2 or more antennas (one baseline), the file has {n_ant}")
    window = float(p["dd_correlation_window_s"])
    if window > 0:  # in samples of the GNSS interval
        t = ds["gnss/t"][:2]
        window = window / float(t[1] - t[0]) if t.size > 1 else 1.0
    fx = gnss_attitude.read_fixed_dd(ds, {"signals": p["dd_signals"], "mask_deg": p["dd_mask_deg"],
                                          "ratio_threshold": p["dd_ratio_threshold"]}, p["dd_method"],
                                     float(p["dd_correlation_s"]), window if window > 0 else np.inf)
    return DDCarrier(fx.t, fx.offsets, fx.los_enu, fx.baseline_b, fx.range_m, fx.cov)


def solve_filter(name):
    cls = {"kf15": KalmanFilter15, "kf21": KalmanFilter21, "hinf": HInfinityFilter, "kf15_dd": KalmanFilter15DD}[name]

    def solve(ds, params, progress=False) -> Solution:
        p = merged(name, params)
        src = attitude_source(ds, p) if name == "kf21" and p["use_attitude"] else None
        truth = truth_inputs(p, src)
        warn_truth(name, truth, TRUTH_KEYS)
        imu, gnss = imu_data(ds), gnss_fixes(ds, p)
        align, found = resolve_align(ds, p, imu, gnss)
        init = initial_state(ds, {**p, "align": align}, imu, gnss, found)
        att = _attitude(ds, p, src) if src is not None else None
        dd = dd_carrier(ds, p) if name == "kf15_dd" else None
        sol = cls(filter_config(ds, {**p, "align": align}, name), init).run(imu, gnss, att, dd=dd)
        extra = {"attitude_source": src} if src is not None else {}
        extra.update(align_used=align, truth_inputs=truth)
        if p["gnss"] == "spp":
            extra["ionosphere_correction"] = broadcast_ionosphere(ds, p)[1]
        return Solution(**{**sol.__dict__, "config": {**sol.config, "params": p, **extra}})

    solve.__doc__ = f"simkit solve --filter {name}: {cls.__doc__.splitlines()[0]}"
    return solve


SOLVERS = {"spp": solve_spp, "kf15": solve_filter("kf15"), "kf15_dd": solve_filter("kf15_dd"),
           "kf21": solve_filter("kf21"), "hinf": solve_filter("hinf")}
