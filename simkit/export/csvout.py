"""``simkit export --format csv``: one CSV per stream in a folder, in a declared convention.

Column names are those the referee reads (docs/referee.md), so a CSV in ``ned-frd`` or ``enu-rfu`` is scored by
``simkit score`` as the HDF5 is; the first line declares the stream and the convention. Numbers are written
with 17 significant digits (a float64 round-trips exactly).

Files: ``truth.csv`` (IMU centre: time, geodetic position, velocity, roll/pitch/heading, quaternion, body rate
and specific force), ``imu.csv`` (gyro, accel), ``antenna_<k>.csv`` (true phase-centre positions at the GNSS
epochs), ``solution_<name>.csv`` (each /solutions group: position, velocity, attitude where present).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import frames
from ..atomic import atomic_open
from .streams import FileStreams, attitude, body_vectors, nav_vectors

_AXES = {"ned-frd": ("ned", "xyz", "frd"), "enu-rfu": ("enu", "xyz", "rfu"), "enu-flu": ("enu", "xyz", "flu")}
_QUAT = {"ned-frd": "q_ned", "enu-rfu": "q_enu", "enu-flu": "q_enu_flu"}


def _write(path: Path, comment: str, columns: dict) -> Path:
    names = list(columns)
    data = np.column_stack([np.asarray(columns[n], dtype=float) for n in names])
    with atomic_open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(f"# {comment}\n")
        f.write(",".join(names) + "\n")
        np.savetxt(f, data, fmt="%.17g", delimiter=",")
    return path


def _time(start, t) -> dict:
    from .. import gpstime

    week, sow = gpstime.add_seconds(np.full(len(t), start[0]), start[1], t)
    return {"t_s": t, "gps_week": week, "gps_sow": sow}


def _nav(frame, prefix, v_enu, unit) -> dict:
    v = nav_vectors(v_enu, frame)
    return {f"{prefix}_{a}_{unit}": v[:, i] for i, a in enumerate(_AXES[frame][0])}


def _attitude(frame, quat_nb, euler) -> dict:
    q = attitude(quat_nb, frame).as_quat(scalar_first=True)
    out = {"roll_deg": np.degrees(euler[:, 1]), "pitch_deg": np.degrees(euler[:, 0]),
           "heading_deg": np.degrees(euler[:, 2])}
    out.update({f"{_QUAT[frame]}_{c}": q[:, i] for i, c in enumerate("wxyz")})
    return out


def _body(frame, prefix, v_rfu, unit) -> dict:
    v = body_vectors(v_rfu, frame)
    return {f"{prefix}_{a}_{unit}": v[:, i] for i, a in enumerate("xyz")}


def _geodetic(pos_ecef) -> dict:
    lla = frames.ecef_to_lla(pos_ecef)
    return {"lat_deg": np.degrees(lla[:, 0]), "lon_deg": np.degrees(lla[:, 1]), "h_m": lla[:, 2]}


def write(streams: FileStreams, out: Path, frame: str = "ned-frd") -> list[Path]:
    """The CSV files of ``streams`` in folder ``out`` (created), in convention ``frame``; returns their paths."""
    out.mkdir(parents=True, exist_ok=True)
    nav, _, body = _AXES[frame]
    head = f"convention {frame}: navigation {nav.upper()}, body {body.upper()} (x, y, z); heading clockwise " \
           f"from north; times GPS"
    tr = streams.truth
    cols = {**_time(streams.start, tr["t"]), **_geodetic(tr["pos_ecef"]), **_nav(frame, "vel", tr["vel_enu"], "m_per_s"),
            **_attitude(frame, tr["quat_nb"], tr["euler"]), **_body(frame, "omega_ib", tr["omega_ib_b"], "rad_per_s"),
            **_body(frame, "f_ib", tr["f_ib_b"], "m_per_s2")}
    paths = [_write(out / "truth.csv", f"simkit export {streams.name}: truth at the IMU centre; {head}", cols)]
    if streams.imu_t is not None:
        cols = {**_time(streams.start, streams.imu_t), **_body(frame, "gyro", streams.gyro, "rad_per_s"),
                **_body(frame, "accel", streams.accel, "m_per_s2")}
        paths.append(_write(out / "imu.csv", f"simkit export {streams.name}: IMU measurements; {head}", cols))
    if streams.antenna_ecef is not None:
        for k in range(streams.antenna_ecef.shape[1]):
            lever = body_vectors(streams.lever_arm_b[k], frame)
            cols = {**_time(streams.start, streams.gnss_t), **_geodetic(streams.antenna_ecef[:, k])}
            paths.append(_write(out / f"antenna_{k}.csv", f"simkit export {streams.name}: true phase centre of "
                                f"antenna {k}, lever arm {body.upper()} {lever.tolist()} m; {head}", cols))
    for name, sol in streams.solutions.items():
        paths.append(_write(out / f"solution_{name}.csv", f"simkit export {streams.name}: /solutions/{name} "
                            f"(point {sol.point}); {head}", solution_columns(streams.start, sol, frame)))
    return paths


def solution_columns(start, sol, frame) -> dict:
    cols = _time(start, sol.t)
    if sol.pos_ecef is not None:
        cols.update(_geodetic(sol.pos_ecef))
    if sol.vel_enu is not None:
        cols.update(_nav(frame, "vel", sol.vel_enu, "m_per_s"))
    if sol.quat_nb is not None:
        euler = sol.euler if sol.euler is not None else frames.euler_from_attitude(
            attitude(sol.quat_nb, "enu-rfu"))
        cols.update(_attitude(frame, sol.quat_nb, euler))
    return cols
