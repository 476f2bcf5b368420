"""GPX 1.0/1.1 tracks and KML/KMZ tracks with timestamps, with the standard library's XML parser.

GPX: every ``trkpt`` of every ``trk``/``trkseg`` in file order, ``lat``/``lon`` attributes (degrees), ``ele``
(m) and ``time`` (ISO 8601 UTC), all required. KML: ``gx:Track`` (``when`` and ``gx:coord`` "lon lat alt"
pairs, in order) or Placemarks each with a ``TimeStamp/when`` and a ``Point`` (a ``LineString`` has no times
and is refused). A KMZ is a zip holding one .kml (``doc.kml`` first).

Heights are taken as ellipsoidal heights: GPX ``ele`` and KML altitude are often above the geoid, a constant
offset of tens of metres that moves the path but not its shape (docs/logs_and_export.md).
"""
from __future__ import annotations

import zipfile
import xml.etree.ElementTree as ET

import numpy as np

from .. import frames
from ..errors import DataFileError
from .record import Record, iso_ns, utc_to_gps_arrays


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def _parse(src, data: bytes):
    try:
        return ET.fromstring(data)
    except ET.ParseError as exc:
        line = exc.position[0] if hasattr(exc, "position") else None
        raise DataFileError(src, f"not well-formed XML: {exc.msg if hasattr(exc, 'msg') else exc}", line) from None


def _record(src, rows) -> Record:
    if not rows:
        raise DataFileError(src, "no timestamped points found")
    ns, lat, lon, h, idx = zip(*rows)
    week, sow = utc_to_gps_arrays(np.array(ns, dtype=np.int64))
    return Record(week, sow, frames.lla_to_ecef(np.radians(lat), np.radians(lon), np.array(h)), np.array(idx),
                  src)


def read_gpx(path) -> Record:
    src = str(path)
    root = _parse(src, _bytes(path))
    if _local(root.tag) != "gpx":
        raise DataFileError(src, f"expected a <gpx> root element, got <{_local(root.tag)}>")
    rows = []
    for k, pt in enumerate((e for e in root.iter() if _local(e.tag) == "trkpt"), 1):
        kids = {_local(c.tag): (c.text or "").strip() for c in pt}
        try:
            if "time" not in kids or "ele" not in kids:
                raise ValueError("needs <ele> and <time>")
            rows.append((iso_ns(kids["time"]), float(pt.attrib["lat"]), float(pt.attrib["lon"]),
                         float(kids["ele"]), k))
        except (KeyError, ValueError) as exc:
            raise DataFileError(src, f"track point {k}: malformed ({exc}): expected lat/lon attributes, <ele> "
                                     f"and an ISO 8601 <time>") from None
    if not rows:
        raise DataFileError(src, "no <trkpt> found (routes and waypoints have no times)")
    return _record(src, rows)


def _bytes(path) -> bytes:
    try:
        with open(path, "rb") as f:
            return f.read()
    except OSError as exc:
        raise DataFileError(str(path), f"cannot read: {exc}") from None


def read_kml(path) -> Record:
    src = str(path)
    if str(path).lower().endswith(".kmz"):
        try:
            with zipfile.ZipFile(path) as z:
                names = sorted((n for n in z.namelist() if n.lower().endswith(".kml")), key=lambda n: n != "doc.kml")
                if not names:
                    raise DataFileError(src, "a KMZ must hold a .kml file")
                data = z.read(names[0])
        except zipfile.BadZipFile:
            raise DataFileError(src, "not a zip archive (a KMZ is a zipped KML)") from None
    else:
        data = _bytes(path)
    root = _parse(src, data)
    rows = []
    tracks = [e for e in root.iter() if _local(e.tag) == "Track"]
    for j, trk in enumerate(tracks, 1):
        whens = [(c.text or "").strip() for c in trk if _local(c.tag) == "when"]
        coords = [(c.text or "").split() for c in trk if _local(c.tag) == "coord"]
        if len(whens) != len(coords):
            raise DataFileError(src, f"gx:Track {j}: {len(whens)} <when> but {len(coords)} <gx:coord>")
        for k, (w, c) in enumerate(zip(whens, coords), 1):
            try:
                rows.append((iso_ns(w), float(c[1]), float(c[0]), float(c[2]), len(rows) + 1))
            except (ValueError, IndexError):
                raise DataFileError(src, f"gx:Track {j} point {k}: expected an ISO 8601 <when> and "
                                         f"'lon lat alt' in <gx:coord>, got {w!r}, {' '.join(c)!r}") from None
    if not tracks:
        for k, pm in enumerate((e for e in root.iter() if _local(e.tag) == "Placemark"), 1):
            when = next((e.text for e in pm.iter() if _local(e.tag) == "when"), None)
            point = next((e for e in pm.iter() if _local(e.tag) == "Point"), None)
            if point is None:
                continue
            if when is None:
                raise DataFileError(src, f"Placemark {k}: a Point without <TimeStamp><when>")
            coord = next((e.text for e in point.iter() if _local(e.tag) == "coordinates"), "") or ""
            try:
                lon, lat, alt = (float(x) for x in coord.strip().split(","))
                rows.append((iso_ns(when), lat, lon, alt, k))
            except ValueError:
                raise DataFileError(src, f"Placemark {k}: expected an ISO 8601 <when> and 'lon,lat,alt' "
                                         f"coordinates, got {when!r}, {coord.strip()!r}") from None
    if not rows:
        raise DataFileError(src, "no timestamped points: expected a gx:Track or Placemarks with TimeStamp and "
                                 "Point (a LineString has no times)")
    return _record(src, rows)
