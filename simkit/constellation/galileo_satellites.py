"""Galileo satellite names -> signal-in-space ids (SVID, RINEX ``Enn``), for TLE sets.

CelesTrak names Galileo objects ``GSAT0101 (GALILEO-PFM)`` (current) or ``GSAT0101 (PRN E11)`` (older sets).
``GSAT_TO_SVID`` maps the GSAT number to the SVID; its source is CelesTrak's own labels in
tests/data/tle/galileo_2020-04-23.txt (26 satellites, TLE epochs 2020-04-19 to 04-23), which agree with the GSC
constellation table of that time. Satellites launched later (GSAT0223 onwards) are not in it: a name-only entry
(``GSAT0223``) is skipped unless the name carries ``(PRN Enn)``. An SVID can be reassigned; a ``(PRN Enn)`` in the
name wins over the table.
"""
from __future__ import annotations

import re

GSAT_TO_SVID = {
    "0101": 11, "0102": 12, "0103": 19, "0104": 20, "0201": 18, "0202": 14, "0203": 26, "0204": 22,
    "0205": 24, "0206": 30, "0207": 7, "0208": 8, "0209": 9, "0210": 1, "0211": 2, "0212": 3, "0213": 4,
    "0214": 5, "0215": 21, "0216": 25, "0217": 27, "0218": 31, "0219": 36, "0220": 13, "0221": 15, "0222": 33,
}
_PRN_E = re.compile(r"\(PRN\s*E\s*(\d+)\)", re.IGNORECASE)
_GSAT = re.compile(r"\bGSAT\s*(\d{4})\b", re.IGNORECASE)


def sat_id(name: str) -> str | None:
    """``Enn`` for a Galileo TLE name, None when the name is not a known Galileo satellite."""
    m = _PRN_E.search(name)
    if m:
        return f"E{int(m.group(1)):02d}"
    m = _GSAT.search(name)
    if m and m.group(1) in GSAT_TO_SVID:
        return f"E{GSAT_TO_SVID[m.group(1)]:02d}"
    return None
