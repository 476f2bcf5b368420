"""The reference trajectory of a simkit file, and its value at any epoch inside its span
(:func:`simkit.io.truth_at`: Hermite position, linear velocity, slerp attitude).

A solution's point (:mod:`simkit.solution`) other than the IMU centre is scored against the truth moved along its
body-frame lever arm l: position p + C_b^e l, Earth-relative velocity v + C_b^n (w_eb^b x l) (ENU at the point)
with w_eb^b = w_ib^b - C_n^b w_ie^n (the body rate w.r.t. the Earth), as the GNSS stage moves its antennas.
"""
from __future__ import annotations

import numpy as np


from .. import frames
from ..io import TRUTH_CORE, Truth, has, open_dataset, read_reference, reference_truth, truth_at  # noqa: F401
from ..io import read_truth as read_file_truth
from ..solution import parse_point
from .errors import RefereeInputError


def read_truth(path, t_min: float | None = None, t_max: float | None = None) -> Truth:
    """The truth (:class:`simkit.io.Truth`: ``t``, ``pos_ecef``, ``vel_enu``, ``quat_nb``, ``omega_ib_b`` when
    present, the antenna lever arms) of the simkit file ``path``; with ``t_min`` / ``t_max`` (s) only the
    samples that bracket that span are read (bounded memory for long files)."""
    with open_dataset(path) as ds:
        if not has(ds, "truth", "t") and read_reference(ds) is not None:
            return reference_truth(ds)
        missing = [k for k in ("t",) + TRUTH_CORE if not has(ds, "truth", k)]
        if missing:
            raise RefereeInputError(path, f"no /truth/{missing[0]} dataset: scoring needs the truth trajectory")
        return read_file_truth(ds, span=(t_min, t_max))


def truth_source(path) -> str:
    """Which truth :func:`read_truth` uses for the file ``path``: "/truth", or "/reference (<its source>)" for a
    real file (``simkit import``), which has no /truth."""
    with open_dataset(path) as ds:
        if has(ds, "truth", "t"):
            return "/truth"
        ref = read_reference(ds)
        return "none" if ref is None else f"/reference ({ref[2]}: {ref[1]})"


def overlap(truth: Truth, t: np.ndarray, where: str = "estimate") -> np.ndarray:
    """Boolean mask of the epochs ``t`` inside the truth span; a clear error when there is none."""
    t = np.asarray(t, dtype=float)
    inside = (t >= truth.t[0]) & (t <= truth.t[-1]) & np.isfinite(t)
    if not inside.any():
        span = f"{t.min():.3f} .. {t.max():.3f} s" if np.isfinite(t).any() and t.size else "no finite epoch"
        raise RefereeInputError(where, f"estimate epochs ({span}) do not overlap the truth span "
                                       f"({truth.t[0]:.3f} .. {truth.t[-1]:.3f} s since the scenario start)")
    return inside


def point_lever(truth: Truth, point: str, where: str = "estimate") -> np.ndarray | None:
    """The body-frame lever arm (3,) m of a solution point from the IMU centre, None for "imu"; a clear error
    for an antenna the file does not have."""
    try:
        kind, value = parse_point(point)
    except ValueError as exc:
        raise RefereeInputError(where, str(exc)) from None
    if kind == "imu":
        return None
    if kind == "lever_b":
        return value
    n = 0 if truth.lever_arm_b is None else len(truth.lever_arm_b)
    if value >= n:
        raise RefereeInputError(where, f"point {point!r}: the truth file has {n} antenna(s) "
                                       f"(/gnss/antennas/lever_arm_b), expected antenna:0 .. antenna:{n - 1}")
    return np.asarray(truth.lever_arm_b[value], dtype=float)


def at_point(ref: Truth, lever_b: np.ndarray | None, where: str = "estimate") -> Truth:
    """The truth ``ref`` (from :func:`truth_at`) moved from the IMU centre by the body-frame lever arm
    ``lever_b`` (3,) m (module docstring); ``ref`` itself for None."""
    if lever_b is None:
        return ref
    if ref.omega_ib_b is None:
        raise RefereeInputError(where, "scoring a point off the IMU centre needs /truth/omega_ib_b in the truth file")
    lla = frames.ecef_to_lla(ref.pos_ecef)
    pos, vel_e, _ = frames.lever_arm_ecef(ref.pos_ecef, frames.enu_to_ecef_vec(ref.vel_enu, lla[:, 0], lla[:, 1]),
                                          ref.quat_nb, ref.omega_ib_b, np.asarray(lever_b, dtype=float)[None])
    pos, vel_e = pos[:, 0], vel_e[:, 0]
    # ENU at the point itself: the two local frames differ by |l| / R (3e-7 rad for 2 m, 0.1 mm/s at 300 m/s)
    lla_point = frames.ecef_to_lla(pos)
    vel = frames.ecef_to_enu_vec(vel_e, lla_point[:, 0], lla_point[:, 1])
    return Truth(ref.t, pos, vel, ref.quat_nb, ref.omega_ib_b, ref.lever_arm_b)
