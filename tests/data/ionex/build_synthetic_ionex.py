"""Write synth1580.16i: a small, SYNTHETIC IONEX 1.0 file (not a measurement) for the parser and interpolation tests.

Layout from the IONEX 1.0 description (Schaer, Gurtner, Feltens 1998): header lines of 60 data columns and a label
in columns 61-80; 2-D maps on a 350 km shell, latitude rows 87.5 .. -87.5 step -5 deg, longitudes -180 .. 180 step
10 deg in 16I5 lines, values in 0.1 TECU (EXPONENT -1), 9999 where missing. Four maps, 2016-06-06 08:00 .. 14:00 UT
every 2 h. The TEC is an analytic daytime bulge that follows the Sun: 5 + 45 cos^2(lat) max(cos(h), 0)^1.5 TECU,
h the local solar hour angle; one cell of the last map is missing (9999) to exercise that path.
Run from anywhere: python tests/data/ionex/build_synthetic_ionex.py
"""
from pathlib import Path

import numpy as np

LATS = np.arange(87.5, -87.6, -5.0)
LONS = np.arange(-180.0, 180.1, 10.0)
HOURS = (8, 10, 12, 14)


def line(data: str, label: str) -> str:
    return f"{data:<60s}{label:<20s}".rstrip() + "\n"


def tec(hour: float) -> np.ndarray:
    lat, lon = np.radians(LATS)[:, None], np.radians(LONS)[None, :]
    h = lon + np.radians(15.0 * (hour - 14.0))  # peak at 14 h local time
    return 5.0 + 45.0 * np.cos(lat) ** 2 * np.maximum(np.cos(h), 0.0) ** 1.5


def main() -> None:
    out = [line(f"{1.0:8.1f}{'':12s}{'I':1s}{'':19s}{'GPS':3s}", "IONEX VERSION / TYPE"),
           line(f"{'build_synthetic_ionex':20s}{'simkit tests':20s}{'24-Nov-26 17:40':20s}", "PGM / RUN BY / DATE"),
           line("SYNTHETIC test map written by build_synthetic_ionex.py", "COMMENT"),
           line("not a measurement: an analytic daytime bulge", "DESCRIPTION"),
           line("".join(f"{v:6d}" for v in (2016, 6, 6, HOURS[0], 0, 0)), "EPOCH OF FIRST MAP"),
           line("".join(f"{v:6d}" for v in (2016, 6, 6, HOURS[-1], 0, 0)), "EPOCH OF LAST MAP"),
           line(f"{7200:6d}", "INTERVAL"),
           line(f"{len(HOURS):6d}", "# OF MAPS IN FILE"),
           line("  COSZ", "MAPPING FUNCTION"),
           line(f"{0.0:8.1f}", "ELEVATION CUTOFF"),
           line(f"{6371.0:8.1f}", "BASE RADIUS"),
           line(f"{2:6d}", "MAP DIMENSION"),
           line(f"  {350.0:6.1f}{350.0:6.1f}{0.0:6.1f}", "HGT1 / HGT2 / DHGT"),
           line(f"  {87.5:6.1f}{-87.5:6.1f}{-5.0:6.1f}", "LAT1 / LAT2 / DLAT"),
           line(f"  {-180.0:6.1f}{180.0:6.1f}{10.0:6.1f}", "LON1 / LON2 / DLON"),
           line(f"{-1:6d}", "EXPONENT"),
           line("TEC values in 0.1 TECU; 9999, if no value available", "COMMENT"),
           line("", "END OF HEADER")]
    for i, hour in enumerate(HOURS):
        values = np.rint(tec(hour) * 10.0).astype(int)
        if i == len(HOURS) - 1:
            values[1, 3] = 9999
        out.append(line(f"{i + 1:6d}", "START OF TEC MAP"))
        out.append(line("".join(f"{v:6d}" for v in (2016, 6, 6, hour, 0, 0)), "EPOCH OF CURRENT MAP"))
        for r, lat in enumerate(LATS):
            out.append(line(f"  {lat:6.1f}{LONS[0]:6.1f}{LONS[-1]:6.1f}{10.0:6.1f}{350.0:6.1f}",
                            "LAT/LON1/LON2/DLON/H"))
            row = values[r]
            for k in range(0, row.size, 16):
                out.append("".join(f"{v:5d}" for v in row[k:k + 16]) + "\n")
        out.append(line(f"{i + 1:6d}", "END OF TEC MAP"))
    out.append(line("", "END OF FILE"))
    (Path(__file__).parent / "synth1580.16i").write_text("".join(out))


if __name__ == "__main__":
    main()
