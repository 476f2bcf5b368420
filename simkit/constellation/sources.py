"""``load(source)``: a file path, a bundled file name (simkit/data/) or ``nominal:<name>``, format detected
from the file's content (RINEX navigation, YUMA, SEM, GSC Galileo XML almanac, TLE)."""
from __future__ import annotations

from pathlib import Path

from ..errors import DataFileError
from .model import Constellation

DATA_DIR = Path(__file__).resolve().parents[1] / "data"
DEFAULT_SKY = "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"


def bundled_files() -> list[str]:
    """Names of the data files shipped in simkit/data/ (usable as ``load`` sources)."""
    return sorted(p.name for p in DATA_DIR.iterdir() if p.is_file() and p.name != "SOURCES.md") \
        if DATA_DIR.is_dir() else []


def resolve(source) -> Path:
    """A path as given if it exists, else a bundled file of that name; DataFileError when neither exists."""
    path = Path(source).expanduser()
    if path.is_file():
        return path
    bundled = DATA_DIR / str(source)
    if bundled.is_file():
        return bundled
    raise DataFileError(source, "no such file, and not a bundled data file "
                        f"(bundled: {', '.join(bundled_files()) or 'none'}; or nominal:gps / nominal:bds)")


def load(source, *, validity_days: float | None = None, systems: str | None = None) -> Constellation:
    """Load a constellation.

    ``source``: ``nominal:gps``, ``nominal:bds`` (= ``nominal:bds3``), ``nominal:bds2``, ``nominal:bds3``,
    ``nominal:gps+bds``, ``nominal:gal``, ``nominal:glo``, ``nominal:gps+bds+gal+glo``; a file path; a bundled
    file name; or ``almanac:<RINEX nav source>`` (an almanac derived
    from the broadcast records nearest the middle of the file, see :func:`almanac.from_ephemeris`). Files: RINEX 3.0x/4.00 navigation (plain or .gz),
    YUMA or SEM GPS almanacs, GSC Galileo almanacs (XML), TLE sets (2- or 3-line). ``validity_days`` (almanac and
    TLE sources only) is the span either side of the almanac/TLE epoch in which states are returned (default 7 days); broadcast
    ephemerides always use their fit interval (GPS, QZSS +-2 h, BDS +-1 h, GLONASS +-30 min; Galileo the latest
    record before t, for 4 h).
    ``systems`` (RINEX navigation files only): the system letters to keep, e.g. ``"GC"`` (default: all of
    G, C, E, J, R in the file).
    """
    text = str(source)
    if text.startswith("almanac:"):
        from . import almanac, kepler

        eph = load(text.split(":", 1)[1])
        if eph.kind != "broadcast":
            raise DataFileError(text, "almanac:<source> needs a broadcast-ephemeris (RINEX navigation) source")
        toe = eph.records.params[eph.records.healthy, kepler.COL["toe"]]
        mid = 0.5 * (toe.min() + toe.max())
        return almanac.from_ephemeris(eph, eph.ref_week, mid, validity_days or almanac.DEFAULT_VALIDITY_DAYS)
    if text.startswith("nominal:"):
        from .nominal import nominal

        return nominal(text.split(":", 1)[1])
    path = resolve(source)
    from . import almanac, galileo_almanac, rinex_nav, tle
    from .textfile import lines_of, read_bytes

    raw = read_bytes(path)
    if rinex_nav.is_rinex_nav(lines_of(raw[:200])):
        return rinex_nav.read(path, raw, systems)
    kw = {} if validity_days is None else {"validity_days": validity_days}
    if galileo_almanac.is_gsc_xml(raw[:500]):
        return galileo_almanac.read(path, raw, **kw)
    lines = lines_of(raw)
    if almanac.is_yuma(lines):
        return almanac.read_yuma(path, lines, **kw)
    if almanac.is_sem(lines):
        return almanac.read_sem(path, lines, **kw)
    if tle.is_tle(lines):
        return tle.read(path, lines, **kw)
    raise DataFileError(path, "unknown format: expected RINEX 2/3/4 navigation, YUMA or SEM almanac, "
                        "GSC Galileo XML almanac, or TLEs", 1)
