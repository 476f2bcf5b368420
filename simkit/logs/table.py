"""CSV logs with declared columns (the names of ``simkit score`` CSVs, docs/referee.md), and ``/solutions``
groups of simkit files.

CSV: a header line of column names, ``#`` comment lines, then one row per sample.
- time: ``gps_week`` + ``gps_sow`` (GPS time), or ``unix_s`` (UTC seconds since 1970), or ``utc`` (ISO 8601);
- position: ``lat_deg, lon_deg, h_m`` or ``lat_rad, lon_rad, h_m`` (WGS-84 ellipsoidal) or
  ``x_ecef_m, y_ecef_m, z_ecef_m``;
- optional velocity ``vel_e_m_per_s, vel_n_m_per_s, vel_u_m_per_s`` or ``vel_n_.., vel_e_.., vel_d_m_per_s``;
- optional attitude ``roll_deg, pitch_deg, heading_deg`` (or ``_rad``; the same numbers in ENU/RFU and NED/FRD);
- optional position standard deviations ``sd_e_m, sd_n_m, sd_u_m`` (or ``sd_d_m``), velocity ones
  ``sd_vel_e_m_per_s`` ... (``sd_vel_d_m_per_s``).
"""
from __future__ import annotations

import numpy as np

from .. import frames
from ..errors import DataFileError
from .record import Record, iso_ns, utc_to_gps_arrays

_DEG = np.pi / 180.0


def _rows(src, text):
    lines = [(n, ln) for n, ln in enumerate(text.splitlines(), 1) if ln.strip() and not ln.lstrip().startswith("#")]
    if len(lines) < 2:
        raise DataFileError(src, "expected a header line of column names and data rows")
    header = [c.strip() for c in lines[0][1].split(",")]
    if len(set(header)) != len(header):
        raise DataFileError(src, "duplicate column names in the header", lines[0][0])
    cells = []
    for n, ln in lines[1:]:
        row = [c.strip() for c in ln.split(",")]
        if len(row) != len(header):
            raise DataFileError(src, f"expected {len(header)} values, got {len(row)}", n)
        cells.append(row)
    return header, cells, np.array([n for n, _ in lines[1:]])


def _numbers(src, header, cells, lines, name):
    j = header.index(name)
    out = np.empty(len(cells))
    for i, row in enumerate(cells):
        try:
            out[i] = float(row[j]) if row[j] else np.nan
        except ValueError:
            raise DataFileError(src, f"column {name}: expected a number, got {row[j]!r}", int(lines[i])) from None
    return out


def _group(src, header, cells, lines, names, what):
    present = [n for n in names if n in header]
    if not present:
        return None
    if len(present) != len(names):
        raise DataFileError(src, f"{what}: missing column(s) {', '.join(n for n in names if n not in header)}")
    return np.stack([_numbers(src, header, cells, lines, n) for n in names], axis=-1)


def read_csv(path) -> Record:
    src = str(path)
    try:
        text = open(path, encoding="utf-8").read()
    except (OSError, UnicodeDecodeError) as exc:
        raise DataFileError(src, f"cannot read: {exc}") from None
    header, cells, lines = _rows(src, text)
    g = lambda names, what: _group(src, header, cells, lines, names, what)
    gps = g(["gps_week", "gps_sow"], "time")
    if gps is not None:
        week, sow = gps[:, 0].astype(np.int64), gps[:, 1]
    elif "unix_s" in header:
        unix = _numbers(src, header, cells, lines, "unix_s")
        week, sow = utc_to_gps_arrays(np.round(unix * 1e9).astype(np.int64))
    elif "utc" in header:
        j = header.index("utc")
        try:
            ns = np.array([iso_ns(r[j]) for r in cells], dtype=np.int64)
        except ValueError:
            bad = next(i for i, r in enumerate(cells) if not _iso_ok(r[j]))
            raise DataFileError(src, f"column utc: expected ISO 8601 UTC, got {cells[bad][j]!r}", int(lines[bad])) from None
        week, sow = utc_to_gps_arrays(ns)
    else:
        raise DataFileError(src, "time: expected gps_week and gps_sow, or unix_s, or utc columns")
    pos = None
    for names, kind in ((["lat_deg", "lon_deg", "h_m"], "deg"), (["lat_rad", "lon_rad", "h_m"], "rad"),
                        (["x_ecef_m", "y_ecef_m", "z_ecef_m"], "ecef")):
        if all(n in header for n in names):
            v = g(names, "position")
            pos = v if kind == "ecef" else frames.lla_to_ecef(*(v * ([_DEG, _DEG, 1.0] if kind == "deg" else 1.0)).T)
            break
    if pos is None:
        raise DataFileError(src, "position: expected lat_deg, lon_deg, h_m (or lat_rad, lon_rad, h_m) or "
                                 "x_ecef_m, y_ecef_m, z_ecef_m columns")
    ned = "vel_d_m_per_s" in header            # the third axis names the convention
    vel = g([f"vel_{a}_m_per_s" for a in ("ned" if ned else "enu")], "velocity")
    vel = frames.ned_to_enu(vel) if ned and vel is not None else vel
    sd_vel = g([f"sd_vel_{a}_m_per_s" for a in ("end" if "sd_vel_d_m_per_s" in header else "enu")], "velocity sigma")
    sd = g(["sd_e_m", "sd_n_m", "sd_d_m" if "sd_d_m" in header else "sd_u_m"], "position sigma")
    euler = None
    for unit, scale in (("deg", _DEG), ("rad", 1.0)):
        rph = g([f"roll_{unit}", f"pitch_{unit}", f"heading_{unit}"], "attitude")
        if rph is not None:
            euler = np.stack([rph[:, 1], rph[:, 0], rph[:, 2]], axis=-1) * scale
            break
    return Record(week, sow, pos, lines, src, sigma_enu=sd, vel_enu=vel, sigma_vel=sd_vel, euler=euler)


def _iso_ok(text):
    try:
        iso_ns(text)
        return True
    except ValueError:
        return False


def read_solution(path, name: str | None) -> Record:
    """A ``/solutions/<name>`` group of a simkit file (the only one when ``name`` is None) as a log: its epochs
    in GPS time (the file's start + t), positions, velocity and attitude where present."""
    from ..io import open_dataset, read_solution as read_sol, solution_names

    src = str(path)
    names = solution_names(path)
    if name is None:
        if len(names) != 1:
            raise DataFileError(src, f"{len(names)} solutions stored ({', '.join(names) or 'none'}): name one "
                                     f"with trajectory.solution")
        name = names[0]
    sol = read_sol(path, name)
    with open_dataset(path) as ds:
        week0, sow0 = int(ds.attrs["start_gps_week"]), float(ds.attrs["start_gps_sow"])
    if sol.pos_ecef is None:
        raise DataFileError(src, f"/solutions/{name} has no positions")
    from .. import gpstime

    ok = np.isfinite(sol.pos_ecef).all(axis=1)
    week, sow = gpstime.add_seconds(np.full(int(ok.sum()), week0), sow0, sol.t[ok])
    f = lambda a: None if a is None else np.asarray(a, float)[ok]
    return Record(week, sow, sol.pos_ecef[ok], np.nonzero(ok)[0], f"{src}:/solutions/{name}",
                  vel_enu=f(sol.vel_enu), euler=f(sol.euler))
