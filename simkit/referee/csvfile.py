"""Third-party estimates as CSV: one header line of column names, then one row per epoch; ``#`` lines are
comments. Column names carry frame and unit; their order is free.

| what | columns (one group of each row) |
|---|---|
| time (required) | ``t_s`` (s since the scenario start) or ``gps_week`` + ``gps_sow`` (GPS time) |
| position | ``lat_deg, lon_deg, h_m`` or ``lat_rad, lon_rad, h_m`` (WGS-84, ellipsoidal) or ``x_ecef_m, y_ecef_m, z_ecef_m`` |
| velocity | ``vel_e_m_per_s, vel_n_m_per_s, vel_u_m_per_s`` (ENU) or ``vel_n_m_per_s, vel_e_m_per_s, vel_d_m_per_s`` (NED) |
| attitude | ``roll_deg, pitch_deg, heading_deg`` (or ``_rad``; the same numbers in ENU/RFU and NED/FRD) or quaternion ``q_enu_w, q_enu_x, q_enu_y, q_enu_z`` (body RFU->ENU) or ``q_ned_w, ..., q_ned_z`` (body FRD->NED) |
| standard deviations (optional) | ``sd_e_m, sd_n_m, sd_u_m`` / ``sd_d_m``; ``sd_vel_e_m_per_s`` ... ``sd_vel_d_m_per_s``; ``sd_roll_deg, sd_pitch_deg, sd_heading_deg`` (or ``_rad``) |
| or a covariance (optional) | ``cov_<a>__<b>`` for covariance state names a, b (``pos_n``, ``vel_d``, ``att_e``, ``heading``, ... see ``compare.STATE_SERIES``), SI units (m^2, m^2/s^2, rad^2, m rad, ...); one of each pair is enough; missing pairs are 0 |

| NIS (optional) | ``nis`` and ``nis_dof``: a filter's normalised innovation squared and its degrees of freedom (empty or 0 where no update) |

The standard deviations give a diagonal covariance (states ``pos_e`` ... ``heading``) for the NEES test.

The position and velocity belong to the IMU centre unless ``point`` (``simkit score --point``) says otherwise:
"antenna:K" for a filter that reports antenna K's phase centre, or "lever_b:[x,y,z]" (body frame, m).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..solution import Solution, parse_point
from .conventions import euler_from_rph, position_ecef, quat_to_simkit
from .errors import RefereeInputError

_DEG = np.pi / 180.0
SD_COLUMNS = {**{f"sd_{a}_m": f"pos_{a}" for a in "endu"},
              **{f"sd_vel_{a}_m_per_s": f"vel_{a}" for a in "endu"},
              **{f"sd_{a}_{u}": a for a in ("roll", "pitch", "heading") for u in ("deg", "rad")}}


def _table(path: Path) -> dict[str, np.ndarray]:
    """Column name -> float array; a clear error naming the line of a malformed row."""
    lines = [(n, line) for n, line in enumerate(path.read_text().splitlines(), 1)
             if line.strip() and not line.lstrip().startswith("#")]
    if len(lines) < 2:
        raise RefereeInputError(path, "expected a header line of column names and at least one data row")
    header = [c.strip() for c in lines[0][1].split(",")]
    if len(set(header)) != len(header):
        raise RefereeInputError(f"{path}:{lines[0][0]}", "duplicate column names in the header")
    rows = []
    for n, line in lines[1:]:
        cells = line.split(",")
        if len(cells) != len(header):
            raise RefereeInputError(f"{path}:{n}", f"expected {len(header)} values, got {len(cells)}")
        try:
            rows.append([float(c) if c.strip() else np.nan for c in cells])
        except ValueError:
            raise RefereeInputError(f"{path}:{n}", "expected numbers separated by commas") from None
    data = np.array(rows, dtype=float)
    return {name: data[:, j] for j, name in enumerate(header)}


def _group(cols, path, names, what, required=False):
    """The columns ``names`` stacked (K, n) when all are present, None when none is; an error when some are."""
    present = [n for n in names if n in cols]
    if len(present) == len(names):
        return np.stack([cols[n] for n in names], axis=-1)
    if present or required:
        missing = [n for n in names if n not in cols]
        raise RefereeInputError(path, f"{what}: missing column(s) {', '.join(missing)}")
    return None


def _one_of(cols, path, options, what):
    """The first complete group among ``options`` [(names, tag)], as (array, tag), or (None, None)."""
    for names, tag in options:
        if all(n in cols for n in names):
            return _group(cols, path, names, what), tag
    for names, _ in options:
        _group(cols, path, names, what)   # a partial group: name what is missing
    return None, None


def _time(cols, path, start):
    if "t_s" in cols:
        return cols["t_s"]
    weeks = _group(cols, path, ["gps_week", "gps_sow"], "time", required=False)
    if weeks is None:
        raise RefereeInputError(path, "time: expected a t_s column, or gps_week and gps_sow")
    if start is None:
        raise RefereeInputError(path, "time: gps_week/gps_sow need the scenario start (score against a file)")
    return (weeks[:, 0] - start[0]) * 604800.0 + (weeks[:, 1] - start[1])


def _attitude(cols, path):
    for unit, scale in (("deg", _DEG), ("rad", 1.0)):
        rph = _group(cols, path, [f"roll_{unit}", f"pitch_{unit}", f"heading_{unit}"], "attitude")
        if rph is not None:
            return euler_from_rph(*(rph * scale).T), None
    q, frame = _one_of(cols, path, [([f"q_{f}_{c}" for c in "wxyz"], f) for f in ("enu", "ned")], "quaternion")
    if q is None:
        return None, None
    return None, quat_to_simkit(q, {"enu": "enu-rfu", "ned": "ned-frd"}[frame], "wxyz", f"{path}: q_{frame}_*")


def _full_covariance(cols, path):
    """``cov_<a>__<b>`` columns as (K, X, X) in the order the states first appear, or (None, ())."""
    from .compare import STATE_SERIES

    pairs = [(c, *c[4:].split("__")) for c in cols if c.startswith("cov_")]
    for col, *names in pairs:
        if len(names) != 2 or any(n not in STATE_SERIES for n in names):
            raise RefereeInputError(path, f"column {col}: expected cov_<a>__<b> with a, b among "
                                          f"{', '.join(STATE_SERIES)}")
    states = list(dict.fromkeys(n for _, a, b in pairs for n in (a, b)))
    if not states:
        return None, ()
    cov = np.zeros((len(next(iter(cols.values()))), len(states), len(states)))
    for col, a, b in pairs:
        i, j = states.index(a), states.index(b)
        cov[:, i, j] = cov[:, j, i] = cols[col]
    return cov, tuple(states)


def _covariance(cols, path):
    names = [state for col, state in SD_COLUMNS.items() if col in cols]
    full = _full_covariance(cols, path)
    if full[0] is not None and names:
        raise RefereeInputError(path, "give either sd_* columns or cov_* columns, not both")
    if not names:
        return full
    scale = [(_DEG if col.endswith("_deg") else 1.0) for col in SD_COLUMNS if col in cols]
    var = (np.stack([cols[c] for c in SD_COLUMNS if c in cols], axis=-1) * scale) ** 2
    return var[:, :, None] * np.eye(len(names)), tuple(names)


def read_csv(path, start: tuple[int, float] | None = None, point: str = "imu") -> Solution:
    """A :class:`Solution` from an estimate CSV (module docstring); ``start`` (GPS week, sow) of the scenario
    converts ``gps_week``/``gps_sow`` times; ``point`` is the point the estimate's position and velocity
    belong to (:mod:`simkit.solution`)."""
    try:
        parse_point(point)
    except ValueError as exc:
        raise RefereeInputError("--point", str(exc).removeprefix("point: ")) from None
    path = Path(path)
    if not path.is_file():
        raise RefereeInputError(path, "no such file")
    cols = _table(path)
    t = _time(cols, path, start)
    geo, unit = _one_of(cols, path, [(["lat_deg", "lon_deg", "h_m"], "deg"), (["lat_rad", "lon_rad", "h_m"], "rad"),
                                     (["x_ecef_m", "y_ecef_m", "z_ecef_m"], "ecef")], "position")
    pos = None
    if geo is not None:
        scale = np.array([_DEG, _DEG, 1.0]) if unit == "deg" else np.ones(3)
        pos = geo if unit == "ecef" else position_ecef(*(geo * scale).T, where=f"{path}: lat_{unit}")
    vel, frame = _one_of(cols, path, [([f"vel_{a}_m_per_s" for a in "enu"], "enu"),
                                      ([f"vel_{a}_m_per_s" for a in "ned"], "ned")], "velocity")
    if frame == "ned":
        vel = vel[:, [1, 0, 2]] * [1.0, 1.0, -1.0]
    euler, quat = _attitude(cols, path)
    cov, names = _covariance(cols, path)
    nis = _group(cols, path, ["nis", "nis_dof"], "NIS")
    extras = {} if nis is None else {"nis": nis[:, 0], "nis_dof": np.nan_to_num(nis[:, 1])}
    return Solution(t=t, pos_ecef=pos, vel_enu=vel, quat_nb=quat, euler=euler, cov=cov, state_names=names,
                    extras=extras, config={"source": str(path)}, point=point)
