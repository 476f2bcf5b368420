"""``simkit export --format kml``: the trajectory (IMU centre) and each antenna's phase centre as KML 2.2
``gx:Track`` placemarks (a ``when`` per point, UTC), for a map; read back by ``[trajectory] source``.

Points are taken every ``1 / rate_hz`` s (default 1 Hz). Coordinates in degrees to 1e-9 deg (0.1 mm) and
heights to 0.1 mm; heights are ellipsoidal (``altitudeMode`` absolute: a viewer draws them above the geoid, a
constant offset of tens of metres).
"""
from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import escape

import numpy as np

from .. import frames, gpstime
from ..atomic import atomic_open
from .streams import FileStreams


def _utc_texts(start, t) -> list[str]:
    base = gpstime.gps_to_utc(*start)
    from datetime import timedelta

    return [(base + timedelta(seconds=float(x))).strftime("%Y-%m-%dT%H:%M:%S.%fZ") for x in t]


def _track(name, start, t, pos_ecef, colour) -> str:
    lla = frames.ecef_to_lla(pos_ecef)
    whens = "".join(f"<when>{w}</when>" for w in _utc_texts(start, t))
    coords = "".join(f"<gx:coord>{np.degrees(lo):.9f} {np.degrees(la):.9f} {h:.4f}</gx:coord>"
                     for la, lo, h in lla)
    return (f"<Placemark><name>{escape(name)}</name><Style><LineStyle><color>{colour}</color><width>3</width>"
            f"</LineStyle></Style><gx:Track><altitudeMode>absolute</altitudeMode>{whens}{coords}</gx:Track>"
            f"</Placemark>\n")


def _every(t, rate_hz):
    if rate_hz is None:
        return np.arange(len(t))
    keep = np.unique(np.searchsorted(t, np.arange(t[0], t[-1] + 1e-9, 1.0 / rate_hz) - 1e-9))
    return keep[keep < len(t)]


def write(streams: FileStreams, out: Path, rate_hz: float | None = 1.0) -> Path:
    tr = streams.truth
    k = _every(tr["t"], rate_hz)
    body = [_track(f"{streams.name}: IMU centre", streams.start, tr["t"][k], tr["pos_ecef"][k], "ff0000ff")]
    if streams.antenna_ecef is not None:
        j = _every(streams.gnss_t, rate_hz)
        for a in range(streams.antenna_ecef.shape[1]):
            body.append(_track(f"antenna {a}", streams.start, streams.gnss_t[j], streams.antenna_ecef[j, a],
                               ["ff00ff00", "ffff0000", "ff00ffff", "ffff00ff"][a % 4]))
    text = ('<?xml version="1.0" encoding="UTF-8"?>\n<kml xmlns="http://www.opengis.net/kml/2.2" '
            'xmlns:gx="http://www.google.com/kml/ext/2.2">\n<Document><name>' + escape(streams.name) + "</name>\n"
            + "".join(body) + "</Document>\n</kml>\n")
    with atomic_open(out, "w", encoding="utf-8") as f:
        f.write(text)
    return out
