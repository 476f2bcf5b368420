"""The dispatch of ``simkit solve``: ``SOLVERS[name](ds, params, progress) -> Solution`` for spp, kf15, kf15_dd,
kf21, hinf; the file is read by :mod:`.adapter`, the alignment chosen by :mod:`.align_policy`.

``params`` are ``--set estimator.key=value`` overrides over ``DEFAULTS`` (an unknown key is an error naming it).
Noise defaults come from the file's ``/imu`` model attributes (white noise, turn-on bias, rate random walk), so
a filter run on simulated data is tuned to the simulated IMU unless told otherwise.
"""
from __future__ import annotations

import numpy as np

from ..params import merge
from ..solution import Solution, warn_truth
from .adapter import attitude_fixes, broadcast_ionosphere, dd_carrier, filter_config, gnss_fixes, imu_data, spp_fixes
from .align_policy import attitude_source, initial_state, resolve_align, static_heading_sigma_deg
from .errors import EstimatorInputError
from .filters import HInfinityFilter, KalmanFilter15, KalmanFilter15DD, KalmanFilter21
from .truth_inputs import TRUTH_KEYS, truth_inputs

COMMON = {"gnss": "spp", "antenna": 0, "elevation_mask_deg": 10.0, "sigma_code_m": 1.0,
          "sigma_doppler_m_per_s": 0.04, "ionosphere": "broadcast", "systems": "", "clock": "per-system",
          "truth_pos_sigma_m": [1.0, 1.0, 5.0], "truth_vel_sigma_m_per_s": 0.05,
          "seed": 0}
FILTER = {"align": "auto", "align_static_s": 10.0, "init_heading_error_deg": 0.0, "p0_att_deg": [1.0, 1.0, 10.0],
          "p0_vel_m_per_s": 0.5, "p0_pos_m": [5.0, 5.0, 10.0], "gyro_arw": None, "accel_vrw": None,
          "gyro_bias_rw": None, "accel_bias_rw": None, "p0_gyro_bias": None, "p0_accel_bias": None,
          "cov_dt_s": 0.1, "pos_sigma_scale": 1.0, "gnss_error_sigma_m": None, "gnss_error_tau_s": 900.0}
DEFAULTS = {"spp": dict(COMMON), "kf15": {**COMMON, **FILTER},
            # no GNSS-error states: the H-infinity bound (theta I) acts on every state, and the part of the fixes'
            # error that no measurement separates from the position grows (height errors of 13-82 m on the scenarios)
            "hinf": {**COMMON, **FILTER, "alpha": 10.0, "gamma_rule": "wu", "gnss_error_sigma_m": [0.0, 0.0, 0.0]},
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


def solve_filter(name):
    cls = {"kf15": KalmanFilter15, "kf21": KalmanFilter21, "hinf": HInfinityFilter, "kf15_dd": KalmanFilter15DD}[name]

    def solve(ds, params, progress=False) -> Solution:
        p = merged(name, params)
        src = attitude_source(ds, p) if name == "kf21" and p["use_attitude"] else None
        truth = truth_inputs(p, src)
        warn_truth(name, truth, TRUTH_KEYS)
        imu, gnss = imu_data(ds), gnss_fixes(ds, p)
        align, found = resolve_align(ds, p, imu, gnss)
        if align == "static":
            p = {**p, "p0_att_deg": static_heading_sigma_deg(ds, p, gnss)}
        init = initial_state(ds, {**p, "align": align}, imu, gnss, found)
        att = attitude_fixes(ds, p, src) if src is not None else None
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
