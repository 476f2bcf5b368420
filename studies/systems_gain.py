"""Visible satellites and DOPs of five systems (GPS, BDS, Galileo, QZSS, GLONASS) against GPS + BDS alone, from
real broadcast ephemerides at two sites (docs/systems.md).

``python -m studies.systems_gain`` prints one Markdown table row per site and system set: mean and minimum
visible count, mean PDOP / HDOP / VDOP (one receiver clock per system), over the span at 10 deg mask.
Sites and spans: Xi'an (34.2 N, 108.9 E, 400 m) over 2026-04-27 02:00-22:00 UTC every 5 min with the bundled
BRDM merged file; KMS3 (Copenhagen, the APPROX POSITION of its 2022 RINEX header) over 2022-06-08 10:00-11:00 UTC
every minute with that station's own RINEX 4 navigation file (only the satellites it tracked that hour).
"""
from __future__ import annotations

from datetime import datetime, timezone

import numpy as np

from simkit import frames, gpstime
from simkit.constellation import dops, load, receiver_view

MASK = np.radians(10.0)
SITES = {
    "Xi'an": (frames.lla_to_ecef(np.radians(34.2), np.radians(108.9), 400.0),
              "BRDM00DLR_S_20261170000_01D_MN.rnx.gz", datetime(2026, 4, 27, 2, tzinfo=timezone.utc), 20 * 3600.0,
              300.0),
    "KMS3": (np.array([3516213.4380, 781859.8595, 5246037.9660]), "KMS300DNK_R_20221591000_01H_MN.rnx.gz",
             datetime(2022, 6, 8, 10, tzinfo=timezone.utc), 3600.0, 60.0),
}


def gains(rx, source, start, span_s, step_s):
    week, sow0 = gpstime.utc_to_gps(start)
    sow = sow0 + np.arange(0.0, span_s + 1e-9, step_s)
    rows = {}
    for label, systems in (("GPS+BDS", "GC"), ("five systems", "GCEJR")):
        const = load(source, systems=systems)
        geo = receiver_view(const, np.broadcast_to(rx, (sow.size, 3)), week, sow)
        with np.errstate(invalid="ignore"):
            n_vis = (geo.elevation >= MASK).sum(axis=1)
        d = dops(geo.elevation, geo.azimuth, MASK, const.system)
        rows[label] = (n_vis.mean(), n_vis.min(), np.nanmean(d["P"]), np.nanmean(d["H"]), np.nanmean(d["V"]))
    return sow.size, rows


def main():
    print("| site | epochs | systems | visible mean | visible min | PDOP | HDOP | VDOP |")
    print("|---|---|---|---|---|---|---|---|")
    for site, (rx, source, start, span, step) in SITES.items():
        n, rows = gains(rx, source, start, span, step)
        for label, (mean, low, p, h, v) in rows.items():
            print(f"| {site} | {n} | {label} | {mean:.1f} | {low} | {p:.2f} | {h:.2f} | {v:.2f} |")


if __name__ == "__main__":
    main()
