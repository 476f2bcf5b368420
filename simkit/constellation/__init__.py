"""GPS, BeiDou, Galileo, QZSS and GLONASS constellations: broadcast ephemerides (RINEX 3/4; GLONASS state vectors
integrated as in :mod:`.glonass`), YUMA/SEM almanacs, TLEs, nominal slots.

``load(source)`` returns a :class:`Constellation` with ``.sat_ids``, ``.system``, ``.orbit_type`` and
``.state(gps_week, gps_sow[, velocity=True])``; :mod:`.geometry` turns states into what a receiver sees
(light time with Earth rotation, ranges, elevation/azimuth, mask, DOPs, visible counts). See docs/constellation.md.
"""
from .antennas import AntennaView, antenna_view
from .errors import ConstellationInputError, NoStateError
from .geometry import Geometry, dops, elevation_azimuth, receiver_view, visible_count
from .model import Constellation, KeplerConstellation, Klobuchar
from .sky import Sky, load_sky
from .sources import DEFAULT_SKY, bundled_files, load

__all__ = [
    "load", "bundled_files", "DEFAULT_SKY", "Constellation", "KeplerConstellation", "Klobuchar", "receiver_view",
    "Geometry", "Sky", "load_sky", "antenna_view", "AntennaView", "elevation_azimuth", "dops", "visible_count",
    "ConstellationInputError", "NoStateError",
]
