"""The alignment policy of the filters: which alignment ``estimator.align`` ("auto", "static", "motion",
"attitude", "truth") resolves to on a file, and the initial navigation state it gives (the maths in
:mod:`.align`). Angles rad, positions geodetic (rad, rad, m), velocities ENU m/s."""
from __future__ import annotations

import numpy as np

from ..frames import ecef_to_lla, quat_from_euler
from ..io import n_antennas
from .adapter import filter_config, solved_attitude
from .align import gyrocompass_heading_sigma, motion_alignment, static_alignment
from .errors import EstimatorInputError
from .inputs import GnssFixes, ImuData, InitialState
from .truth_inputs import truth_start

AUTO_ATTITUDE_S = 300.0   # align = "auto" looks for a fixed attitude in the first 300 s only
STATIC_SPEED_M_S = 0.5    # stationary start: every GNSS speed in the first align_static_s below this
STATIC_FORCE_STD = 0.1    # and the IMU specific-force magnitude steadier than this (m/s^2, sd)
MOTION_SPEED_M_S = 5.0    # "motion" alignment: the first GNSS fix with a horizontal speed above this


def _attitude_alignment(ds, p, gnss: GnssFixes, good, stop_s: float | None = None):
    """([pitch, roll, heading] rad, GNSS fix index): the first fixed epoch of the attitude solver (epochs up to
    ``stop_s`` s; None: all) that has a GNSS fix at the same time."""
    if n_antennas(ds) < 3:
        raise EstimatorInputError(f"estimator.align: 'attitude' needs 3 or more antennas, {ds.path} has "
                                  f"{n_antennas(ds)}")
    att = solved_attitude(ds, {"attitude_method": p.get("attitude_method", "attitude")},
                          {} if stop_s is None else {"stop_s": float(stop_s)})
    both = np.flatnonzero(np.isin(np.round(gnss.t[good], 6), np.round(att.t, 6)))
    if both.size == 0:
        raise EstimatorInputError("estimator.align: 'attitude' found no epoch with fixed ambiguities and a GNSS fix")
    g0 = good[both[0]]
    return att.euler[np.argmin(np.abs(att.t - gnss.t[g0]))], g0


def gyrocompass_sigma(ds, p, lat: float) -> float:
    """Heading uncertainty (rad, 1 sigma) of gyrocompassing over ``align_static_s`` at latitude ``lat`` rad with the
    filter's gyro model (its initial bias sigma, and the angle random walk averaged over the span): the bias and the
    noise read as a tilt of the horizontal Earth rate, Omega_e cos(lat) ~ 15 deg/h cos(lat). A MEMS gyro's bias of
    tens to hundreds of deg/h leaves the heading undetermined (tens of degrees or more); a navigation-grade one,
    well under a degree."""
    cfg = filter_config(ds, p, None)
    noise = np.hypot(cfg.p0_gyro_bias, cfg.gyro_arw / np.sqrt(max(float(p["align_static_s"]), 1e-3)))
    return gyrocompass_heading_sigma(noise, lat)


def _static_start(p, imu: ImuData, lla_ant):
    """(euler rad, zero velocity) from levelling and gyrocompassing over the first ``align_static_s``."""
    n = max(2, int(np.searchsorted(imu.t, imu.t[0] + float(p["align_static_s"]))))
    rates = imu.gyro[:n] if not imu.increments else imu.gyro[1:n] / np.diff(imu.t[:n])[:, None]
    force = imu.accel[:n] if not imu.increments else imu.accel[1:n] / np.diff(imu.t[:n])[:, None]
    euler, _ = static_alignment(rates, force, lla_ant[0])
    return euler, np.zeros(3)


def _motion_start(ds, gnss: GnssFixes, good):
    """(euler rad, velocity ENU m/s, GNSS fix index) at the first GNSS fix faster than MOTION_SPEED_M_S."""
    moving = good[np.hypot(gnss.vel_enu[good, 0], gnss.vel_enu[good, 1]) > MOTION_SPEED_M_S]
    if moving.size == 0:
        raise EstimatorInputError(f"estimator.align: 'motion' needs a GNSS speed above {MOTION_SPEED_M_S:g} "
                                  f"m/s, {ds.path} has none; try 'static' or 'auto'")
    g0 = moving[0]
    return motion_alignment(gnss.vel_enu[g0]), gnss.vel_enu[g0], g0


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
    lla = ecef_to_lla(gnss.pos_ecef[g0])  # static and motion: the lever arm (metres) is left to the P0 of position
    if p["align"] == "truth":
        euler, lla, vel = truth_start(ds)
    elif p["align"] == "attitude":
        euler, g0 = found if found is not None else _attitude_alignment(ds, p, gnss, good)
        vel, lla = gnss.vel_enu[g0], ecef_to_lla(gnss.pos_ecef[g0])
    elif p["align"] == "static":
        euler, vel = _static_start(p, imu, lla)
    elif p["align"] == "motion":
        euler, vel, g0 = _motion_start(ds, gnss, good)
        lla = ecef_to_lla(gnss.pos_ecef[g0])
    else:
        raise EstimatorInputError(f"estimator.align: expected 'static', 'motion', 'truth' or 'attitude', "
                                  f"got {p['align']!r}")
    euler = np.asarray(euler, float) + [0.0, 0.0, np.radians(float(p["init_heading_error_deg"]))]
    t0 = float(gnss.t[g0]) if p["align"] in ("motion", "attitude") else float(imu.t[0])
    return InitialState(t0, np.asarray(lla, float), np.asarray(vel, float), quat_from_euler(*euler))


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
    "static" when the start is stationary (:func:`stationary_start`) and the gyros can find north in it
    (:func:`gyrocompass_sigma` within the filter's initial heading sigma, ``p0_att_deg[2]``), else "motion" when
    some GNSS fix is faster than MOTION_SPEED_M_S, else "static" (levelling is all that is left on a slow
    platform; :func:`static_heading_sigma_deg` then widens the initial heading sigma to what gyrocompassing
    gives)."""
    if p["align"] != "auto":
        return p["align"], None
    good = np.flatnonzero(np.isfinite(gnss.pos_ecef).all(1))
    if n_antennas(ds) >= 3 and good.size:
        try:
            return "attitude", _attitude_alignment(ds, p, gnss, good, float(gnss.t[good[0]]) + AUTO_ATTITUDE_S)
        except EstimatorInputError:
            pass
    fast = np.hypot(gnss.vel_enu[good, 0], gnss.vel_enu[good, 1]) > MOTION_SPEED_M_S
    if stationary_start(p, imu, gnss) and good.size:
        lat = ecef_to_lla(gnss.pos_ecef[good[0]])[0]
        heading_p0 = np.radians(np.broadcast_to(np.asarray(p["p0_att_deg"], float), 3)[2])
        if gyrocompass_sigma(ds, p, lat) <= heading_p0 or not fast.any():
            return "static", None
    return ("motion" if fast.any() else "static"), None


def static_heading_sigma_deg(ds, p, gnss: GnssFixes) -> list[float]:
    """``p['p0_att_deg']`` for a static alignment: the heading sigma widened to :func:`gyrocompass_sigma` where
    that is larger (capped at 180 deg: a MEMS gyro finds no north, and a filter told 10 deg would trust a heading
    that is anywhere)."""
    p0 = [float(x) for x in np.broadcast_to(np.asarray(p["p0_att_deg"], float), 3)]
    good = np.flatnonzero(np.isfinite(gnss.pos_ecef).all(1))
    if good.size:
        lat = ecef_to_lla(gnss.pos_ecef[good[0]])[0]
        p0[2] = max(p0[2], min(180.0, float(np.degrees(gyrocompass_sigma(ds, p, lat)))))
    return p0


def attitude_source(ds, p) -> str:
    """``p['attitude_source']`` with "auto" resolved: "attitude" (simkit's own carrier-phase attitude) when the
    file has 3 or more antennas, else "none" (no attitude updates: a default never reads the truth);
    "attitude" with fewer than 3 antennas is an error naming the key."""
    n_ant = n_antennas(ds)
    src = p["attitude_source"]
    if src == "auto":
        return "attitude" if n_ant >= 3 else "none"
    if src == "attitude" and n_ant < 3:
        raise EstimatorInputError(f"estimator.attitude_source: 'attitude' needs 3 or more antennas (pitch, roll "
                                  f"and heading), {ds.path} has {n_ant}; use 'none' (or kf15_dd, whose DD "
                                  f"update takes one baseline)")
    return src
