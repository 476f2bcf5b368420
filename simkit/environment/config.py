"""The [environment] scenario section: buildings (GeoJSON), parametric street canyons and body masks.

Keys (units in their names; heights are above the trajectory's reference point, the IMU centre at t = 0):

- ``buildings``: a GeoJSON file of building footprints (path relative to the scenario file, else the working
  folder), ``height_property`` (default "height") its height property in metres, ``height_offset_m`` added to
  every height (e.g. minus the IMU centre's height above the street);
- ``canyon``: one inline table or ``[[environment.canyon]]`` tables with ``width_m``, ``height_m``
  (or ``left_height_m`` / ``right_height_m``), ``azimuth_deg`` of the street axis (clockwise from north),
  ``length_m`` (default 1000) and ``centre_en_m`` = [east, north] of its middle from the origin (default [0, 0]:
  a canyon on a static trajectory is centred on it);
- ``reflections`` (default true), ``reflection_range_m`` (default 300: reflection points farther away,
  horizontally, are ignored), ``reflection_loss_db`` (default 6: the reflected signal's power loss);
- ``[[environment.body_mask]]``: ``azimuth_deg`` / ``elevation_deg`` tables in the body frame (azimuth clockwise
  from forward), for ``antennas`` (default all); ``[[environment.body_box]]``: ``min_m`` / ``max_m`` corners in
  the body frame, for ``antennas`` (default all).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ScenarioError
from ..section import Section, in_range, non_negative, positive
from .body import Box, MaskTable
from .geojson import read_footprints
from .walls import Walls, canyon_walls, footprint_walls

GRID_CELL_M = 25.0


@dataclass(frozen=True)
class EnvironmentConfig:
    """The resolved environment: walls in the origin's local plane, reflection settings, body masks."""

    walls: Walls
    buildings: str | None
    n_canyons: int
    reflections: bool
    reflection_range_m: float
    reflection_loss_db: float
    mask_tables: tuple[MaskTable, ...]
    boxes: tuple[Box, ...]
    grid_cell_m: float = GRID_CELL_M


def parse_config(sec: Section, origin_lla, base_dir: Path | None = None) -> EnvironmentConfig:
    """Read the ``[environment]`` table; ``origin_lla`` = (lat rad, lon rad, height m) of the trajectory origin,
    ``base_dir`` the scenario file's folder. Raises ScenarioError naming the key (DataFileError for the
    GeoJSON file's content)."""
    parts, source = [], None
    if sec.has("buildings"):
        source = sec.get("buildings", str)
        path = find_file(source, base_dir)
        if path is None:
            raise sec.error("buildings", f"no such file {source!r} (relative paths are taken from the scenario's "
                            "folder, then the working folder)")
        prop = sec.get("height_property", str, "height")
        offset = sec.get("height_offset_m", float, 0.0)
        feet = read_footprints(path, prop)
        parts.append(footprint_walls([_lonlat_to_en(f.lonlat_deg, origin_lla) for f in feet],
                                     [f.height_m + offset for f in feet]))
    canyons = sec.sections("canyon")
    for c in canyons:
        parts.append(_canyon(c))
        c.done()
    cfg = EnvironmentConfig(
        walls=Walls.concat(parts), buildings=source, n_canyons=len(canyons),
        reflections=sec.get("reflections", bool, True),
        reflection_range_m=sec.get("reflection_range_m", float, 300.0, check=positive),
        reflection_loss_db=sec.get("reflection_loss_db", float, 6.0, check=in_range(0.01, 60.0)),
        mask_tables=tuple(_mask(s) for s in _each(sec.sections("body_mask"))),
        boxes=tuple(_box(s) for s in _each(sec.sections("body_box"))))
    sec.done()
    return cfg


def check_antennas(cfg: EnvironmentConfig, lever_b: np.ndarray) -> None:
    """Body masks must name existing antennas, and no antenna may sit inside a body box."""
    n = lever_b.shape[0]
    for kind, items in (("body_mask", cfg.mask_tables), ("body_box", cfg.boxes)):
        for i, item in enumerate(items):
            bad = [a for a in item.antennas or () if not 0 <= a < n]
            if bad:
                raise ScenarioError(f"environment.{kind}[{i}].antennas", f"antenna {bad[0]} does not exist "
                                    f"(expected indices 0 .. {n - 1})")
    for i, box in enumerate(cfg.boxes):
        for a in range(n) if box.antennas is None else box.antennas:
            if np.all((lever_b[a] > box.lo) & (lever_b[a] < box.hi)):
                raise ScenarioError(f"environment.body_box[{i}]", f"antenna {a} (lever arm {lever_b[a].tolist()}) "
                                    "is inside the box: it would block every satellite")


def find_file(name: str, base_dir: Path | None) -> Path | None:
    """The file ``name`` relative to the scenario's folder ``base_dir``, else the working folder; None if neither."""
    for cand in ([base_dir / name] if base_dir is not None else []) + [Path(name)]:
        if cand.is_file():
            return cand
    return None


def _lonlat_to_en(lonlat_deg: np.ndarray, origin_lla) -> np.ndarray:
    """East, north (K, 2) m in the origin's local plane of [longitude, latitude] degrees (at the origin's
    height)."""
    import pymap3d

    lat0, lon0, h0 = origin_lla
    e, n, _ = pymap3d.geodetic2enu(lonlat_deg[:, 1], lonlat_deg[:, 0], h0, np.degrees(lat0), np.degrees(lon0), h0)
    return np.stack([e, n], axis=-1)


def _each(sections):
    for s in sections:
        yield s
        s.done()


def _canyon(c: Section) -> Walls:
    width = c.get("width_m", float, check=positive)
    height = c.get("height_m", float, None, check=non_negative)
    left = c.get("left_height_m", float, height, check=non_negative)
    right = c.get("right_height_m", float, height, check=non_negative)
    if left is None or right is None:
        raise c.error("height_m", "missing required key (expected a number: the walls' height in metres above "
                      "the reference point; or left_height_m and right_height_m)")
    return canyon_walls(np.asarray(c.get("centre_en_m", float, [0.0, 0.0], shape=2)),
                        np.radians(c.get("azimuth_deg", float, 0.0)), width,
                        c.get("length_m", float, 1000.0, check=positive), left, right)


def _antennas(s: Section):
    ants = s.get("antennas", int, None, shape=0)
    return tuple(ants) if ants is not None else None


def _mask(s: Section) -> MaskTable:
    az = np.asarray(s.get("azimuth_deg", float, shape=0))
    el = np.asarray(s.get("elevation_deg", float, shape=0))
    if az.size == 0 or az.size != el.size:
        raise s.error("elevation_deg", f"expected one elevation per azimuth ({az.size}), got {el.size}")
    if (az < 0).any() or (az >= 360).any() or (np.diff(az) <= 0).any():
        raise s.error("azimuth_deg", "expected increasing azimuths in [0, 360)")
    if (np.abs(el) > 90).any():
        raise s.error("elevation_deg", "expected elevations in [-90, 90]")
    return MaskTable(np.radians(az), np.radians(el), _antennas(s))


def _box(s: Section) -> Box:
    lo = np.asarray(s.get("min_m", float, shape=3))
    hi = np.asarray(s.get("max_m", float, shape=3))
    if (hi <= lo).any():
        raise s.error("max_m", f"expected every coordinate above min_m {lo.tolist()}, got {hi.tolist()}")
    return Box(lo, hi, _antennas(s))


