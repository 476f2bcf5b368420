"""Building footprints from a GeoJSON file (RFC 7946): Polygon and MultiPolygon features with a height property.

Coordinates are [longitude, latitude] in degrees (WGS-84); each polygon's outer ring gives the footprint (holes,
courtyards, are left out: their walls face inwards and are rarely seen from a street). The height (m) is a number
property of each feature. Read with the standard ``json`` module; every defect is one :class:`DataFileError`
naming the file and the feature.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import DataFileError


@dataclass(frozen=True)
class Footprint:
    """One building: outer ring (K, 2) [longitude, latitude] degrees and its height m."""

    lonlat_deg: np.ndarray
    height_m: float


def read_footprints(path, height_property: str = "height") -> list[Footprint]:
    """Footprints of the Polygon / MultiPolygon features of the GeoJSON file ``path`` (a FeatureCollection, a
    single Feature or a bare geometry is refused: heights live in feature properties)."""
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise DataFileError(path, f"cannot read: {exc.strerror or exc}") from None
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DataFileError(path, f"not valid JSON: {exc}") from None
    if isinstance(doc, dict) and doc.get("type") == "Feature":
        features = [doc]
    elif isinstance(doc, dict) and doc.get("type") == "FeatureCollection" and isinstance(doc.get("features"), list):
        features = doc["features"]
    else:
        raise DataFileError(path, "expected a GeoJSON FeatureCollection (or Feature) of building footprints")
    out = []
    for i, feat in enumerate(features):
        out += _feature(path, i, feat, height_property)
    if not out:
        raise DataFileError(path, "no Polygon or MultiPolygon feature: expected building footprints")
    return out


def _feature(path, i, feat, height_property) -> list[Footprint]:
    name = f"feature {i}"
    if not isinstance(feat, dict) or feat.get("type") != "Feature":
        raise DataFileError(path, f"{name}: expected an object with \"type\": \"Feature\"")
    props = feat.get("properties") or {}
    if isinstance(props, dict) and props.get("id", feat.get("id")) is not None:
        name += f" (id {props.get('id', feat.get('id'))})"
    geom = feat.get("geometry")
    if not isinstance(geom, dict) or geom.get("type") not in ("Polygon", "MultiPolygon"):
        kind = geom.get("type") if isinstance(geom, dict) else type(geom).__name__
        raise DataFileError(path, f"{name}: geometry {kind!r}: expected a Polygon or MultiPolygon footprint")
    h = props.get(height_property) if isinstance(props, dict) else None
    if isinstance(h, str):
        try:
            h = float(h.strip().removesuffix("m").strip())
        except ValueError:
            h = None
    if isinstance(h, bool) or not isinstance(h, (int, float)) or not math.isfinite(h) or h <= 0:
        raise DataFileError(path, f"{name}: property {height_property!r} = {props.get(height_property)!r}: expected "
                            f"a positive height in metres")
    polys = [geom.get("coordinates")] if geom["type"] == "Polygon" else geom.get("coordinates")
    if not isinstance(polys, list) or not polys:
        raise DataFileError(path, f"{name}: {geom['type']} without coordinates")
    return [Footprint(_ring(path, name, poly), float(h)) for poly in polys]


def _ring(path, name, poly) -> np.ndarray:
    try:
        ring = np.asarray(poly[0], dtype=float)
    except (TypeError, ValueError, IndexError):
        ring = None
    if ring is None or ring.ndim != 2 or ring.shape[1] not in (2, 3) or ring.shape[0] < 4:
        raise DataFileError(path, f"{name}: expected an outer ring of at least 4 [longitude, latitude] positions")
    ring = ring[:, :2]
    if not np.isfinite(ring).all() or (np.abs(ring[:, 1]) > 90).any() or (np.abs(ring[:, 0]) > 180).any():
        raise DataFileError(path, f"{name}: coordinates outside longitude [-180, 180], latitude [-90, 90]")
    if not np.array_equal(ring[0], ring[-1]):
        raise DataFileError(path, f"{name}: the outer ring is not closed (first and last positions differ)")
    return ring
