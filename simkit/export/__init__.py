"""``simkit export``: a simkit file as a ROS 2 bag, CSV files per stream, or KML tracks (docs/logs_and_export.md).
Conventions stay simkit's inside and are converted here, at the edge (:mod:`.streams`)."""
from __future__ import annotations

from pathlib import Path

from ..errors import InputError, OutputError
from .choices import BODY_FRAMES, FORMATS, STAMPS

__all__ = ["FORMATS", "BODY_FRAMES", "STAMPS", "export"]


def export(path, fmt: str, out, frame: str = "ned-frd", stamp: str = "unix", fix_sigma_m: float = 0.0,
           seed: int = 0, rate_hz: float | None = 1.0) -> list[Path]:
    """Write ``path`` (a simkit file) as ``fmt`` at ``out`` (a folder for rosbag2 and csv, a file for kml);
    returns the written paths. ``frame``: the CSV convention; ``stamp``, ``fix_sigma_m``, ``seed``: the bag's
    stamps and NavSatFix noise; ``rate_hz``: the KML point rate (None: every sample)."""
    if fmt not in FORMATS:
        raise InputError("--format", f"expected one of {', '.join(FORMATS)}, got {fmt!r}")
    if frame not in BODY_FRAMES:
        raise InputError("--frame", f"expected one of {', '.join(BODY_FRAMES)}, got {frame!r}")
    if stamp not in STAMPS:
        raise InputError("--stamp", f"expected one of {', '.join(STAMPS)}, got {stamp!r}")
    if fix_sigma_m < 0:
        raise InputError("--fix-sigma-m", f"expected a number >= 0, got {fix_sigma_m!r}")
    out = Path(out)
    if fmt == "rosbag2":
        import importlib.util

        if importlib.util.find_spec("rosbags") is None:
            raise InputError("--format rosbag2", "needs the 'rosbags' package: pip install 'simkit[export]'")
        _replaceable_bag(out)
    from .streams import read_streams  # here: the parser of `simkit export` imports this package

    streams = read_streams(path)
    if fmt == "csv":
        from . import csvout

        return csvout.write(streams, out, frame)
    if fmt == "kml":
        from . import kmlout

        return [kmlout.write(streams, out, rate_hz)]
    from . import rosbag

    return [rosbag.write(streams, out, stamp, fix_sigma_m, seed)]


def _replaceable_bag(out: Path) -> None:
    """A bag replaces only an earlier bag (a folder holding nothing but metadata.yaml and .db3/.mcap files)."""
    if out.is_dir() and any(p.name != "metadata.yaml" and p.suffix not in (".db3", ".mcap") for p in out.iterdir()):
        raise OutputError(out, "exists and is not a rosbag2 folder: expected a new folder name or an earlier bag "
                               "to replace")
