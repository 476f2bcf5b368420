"""Galileo almanacs in the European GNSS Service Centre (GSC) XML format.

A GSC almanac file holds ``signalData/header/GAL-header/issueDate`` (ISO 8601 UTC) and, under
``signalData/body/Almanacs``, one ``svAlmanac`` per satellite: ``SVID`` and an ``almanac`` element with the
I/NAV almanac words of the Galileo OS SIS ICD (5.1.10, Table 70), in these units:

- ``aSqRoot``: sqrt(A) minus the nominal sqrt(A_nominal) = sqrt(29,600,000 m) = 5440.588203494 m^0.5
- ``ecc``; ``deltai``: inclination minus 56 deg, semicircles
- ``omega0``, ``w``, ``m0``: semicircles; ``omegaDot``: semicircles/s
- ``af0`` s, ``af1`` s/s; ``iod``; ``t0a`` s of GST week; ``wna``: the GST week modulo 4

plus ``svINavSignalStatus`` (``statusE1B``, ``statusE5b``) and ``svFNavSignalStatus`` (``statusE5a``); a satellite
is healthy when every status given is 0. The full week is the week congruent to ``wna`` (mod 4) nearest the issue
date's (GST weeks count from GPS week 1024, a multiple of 4, so the residue is the same in GPS weeks). GST is
taken as GPS time (RINEX writes Galileo times on the GPS week count; the GGTO offset is a few ns).

The orbit is the almanac model of the ICD: Keplerian with the Galileo constants, no harmonic corrections and no
mean-motion correction; clock af0 + af1 (t - t0a) plus the relativistic term. States within ``validity_days``
(default 7) of t0a, NaN outside.
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from datetime import datetime, timezone

import numpy as np

from .. import gpstime
from ..errors import DataFileError
from . import kepler
from .model import KeplerConstellation, Records
from .systems import GAL

NOMINAL_SQRT_A = 5440.588203494  # m^0.5, sqrt(29,600,000 m) (OS SIS ICD Table 70 note)
NOMINAL_INCLINATION_RAD = math.radians(56.0)
DEFAULT_VALIDITY_DAYS = 7.0
FIELDS = ("aSqRoot", "ecc", "deltai", "omega0", "omegaDot", "w", "m0", "af0", "af1", "iod", "t0a", "wna")
STATUS = ("statusE1B", "statusE5b", "statusE5a")


def is_gsc_xml(head: bytes) -> bool:
    """True for the start of a GSC almanac XML file."""
    text = head.decode("latin-1")
    return text.lstrip().startswith("<") and ("<signalData" in text or "<svAlmanac" in text)


def _line_of(raw: bytes, needle: str, start: int = 0) -> int:
    """1-based line of the first ``needle`` at or after byte ``start`` (for error messages)."""
    k = raw.find(needle.encode(), start)
    return raw.count(b"\n", 0, max(k, 0)) + 1


def _issue_week(root, path, raw) -> int:
    node = root.find("./header/GAL-header/issueDate")
    if node is None or not (node.text or "").strip():
        raise DataFileError(path, "missing header/GAL-header/issueDate: the 2-bit almanac week (wna) cannot be "
                            "resolved to a full week without it")
    text = node.text.strip()
    try:
        when = datetime.fromisoformat(text.replace("Z", "+00:00"))
    except ValueError:
        raise DataFileError(path, f"issueDate: expected an ISO 8601 date and time, found {text!r}",
                            _line_of(raw, "<issueDate")) from None
    if when.tzinfo is None:
        when = when.replace(tzinfo=timezone.utc)
    if when.year < 1999:
        raise DataFileError(path, f"issueDate {text!r} is before Galileo system time began (1999-08-22)",
                            _line_of(raw, "<issueDate"))
    week, _ = gpstime.utc_to_gps(when)
    return int(week)


def _number(sv, name, path, line, svid):
    node = sv.find(name)
    if node is None or not (node.text or "").strip():
        raise DataFileError(path, f"SVID {svid}: missing {name}", line)
    text = node.text.strip()
    try:
        value = float(text)
    except ValueError:
        raise DataFileError(path, f"SVID {svid}: {name}: expected a number, found {text!r}", line) from None
    if not math.isfinite(value):
        raise DataFileError(path, f"SVID {svid}: {name}: expected a finite number, found {text!r}", line)
    return value


def read(path, raw: bytes, validity_days: float = DEFAULT_VALIDITY_DAYS) -> KeplerConstellation:
    """Parse a GSC Galileo almanac (XML bytes) into a constellation of E-satellites."""
    try:
        root = ET.fromstring(raw)
    except ET.ParseError as exc:
        raise DataFileError(path, f"not well-formed XML (truncated?): {exc.msg if hasattr(exc, 'msg') else exc}",
                            exc.position[0]) from None
    for node in root.iter():  # element names without a namespace, should a file declare one
        if isinstance(node.tag, str) and "}" in node.tag:
            node.tag = node.tag.split("}", 1)[1]
    week_issue = _issue_week(root, path, raw)
    svs = root.findall("./body/Almanacs/svAlmanac")
    if not svs:
        raise DataFileError(path, "no body/Almanacs/svAlmanac element: expected a GSC Galileo almanac")
    rows, pos = [], 0
    for sv in svs:
        pos = raw.find(b"<svAlmanac", pos) + 1
        line = _line_of(raw, "<svAlmanac", pos - 1)
        svid_text = (sv.findtext("SVID") or "").strip()
        if not svid_text.isdigit() or not 1 <= int(svid_text) <= 36:
            raise DataFileError(path, f"SVID: expected an integer 1-36, found {svid_text!r}", line)
        svid = int(svid_text)
        alm = sv.find("almanac")
        if alm is None:
            raise DataFileError(path, f"SVID {svid}: missing almanac element", line)
        v = {name: _number(alm, name, path, line, svid) for name in FIELDS}
        if v["wna"] not in (0.0, 1.0, 2.0, 3.0):
            raise DataFileError(path, f"SVID {svid}: wna: expected the almanac week modulo 4 (0-3), "
                                f"found {v['wna']:g}", line)
        if not 0 <= v["t0a"] < gpstime.SECONDS_PER_WEEK:
            raise DataFileError(path, f"SVID {svid}: t0a: expected 0-604800 s, found {v['t0a']:g}", line)
        if not 0 <= v["ecc"] < 1:
            raise DataFileError(path, f"SVID {svid}: ecc: expected 0 <= e < 1, found {v['ecc']:g}", line)
        status = [int(_number(sv, f"{grp}/{name}", path, line, svid))
                  for grp, name in (("svINavSignalStatus", "statusE1B"), ("svINavSignalStatus", "statusE5b"),
                                    ("svFNavSignalStatus", "statusE5a"))
                  if sv.find(f"{grp}/{name}") is not None]
        v.update(svid=svid, line=line, healthy=all(s == 0 for s in status),
                 week=week_issue + (int(v["wna"]) - week_issue + 2) % 4 - 2)
        rows.append(v)
    return _constellation(rows, path, validity_days)


def _constellation(rows, path, validity_days) -> KeplerConstellation:
    rows = sorted(rows, key=lambda r: r["svid"])
    ids = [r["svid"] for r in rows]
    dup = sorted({s for s in ids if ids.count(s) > 1})
    if dup:
        raise DataFileError(path, f"SVID {dup[0]} appears more than once", rows[ids.index(dup[0])]["line"])
    ref_week = min(r["week"] for r in rows)
    p = kepler.empty_table(len(rows))
    c = kepler.COL
    pi = math.pi
    for k, r in enumerate(rows):
        t = (r["week"] - ref_week) * gpstime.SECONDS_PER_WEEK + r["t0a"]
        p[k, c["toe"]] = p[k, c["toc"]] = t
        p[k, c["toe_sow"]] = r["t0a"]
        p[k, c["sqrt_a"]] = NOMINAL_SQRT_A + r["aSqRoot"]
        p[k, c["e"]] = r["ecc"]
        p[k, c["i0"]] = NOMINAL_INCLINATION_RAD + r["deltai"] * pi
        p[k, c["omega0"]] = r["omega0"] * pi
        p[k, c["omega_dot"]] = r["omegaDot"] * pi
        p[k, c["omega"]] = r["w"] * pi
        p[k, c["m0"]] = r["m0"] * pi
        p[k, c["af0"]], p[k, c["af1"]] = r["af0"], r["af1"]
        p[k, c["mu"]], p[k, c["omega_e"]], p[k, c["rel_f"]] = GAL.mu, GAL.omega_e, GAL.rel_f
    n = len(rows)
    records = Records(p, np.arange(n), np.array([r["healthy"] for r in rows]),
                      np.full(n, validity_days * gpstime.SECONDS_PER_DAY))
    return KeplerConstellation([f"E{s:02d}" for s in ids], records, str(path), ref_week, "almanac")
