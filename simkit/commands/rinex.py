"""``simkit rinex FILE.h5 [-o DIR]``: RINEX 3.04 observation files per antenna plus the navigation data used."""
from __future__ import annotations


def add_parser(sub):
    p = sub.add_parser("rinex", help="export the GNSS observables of a simkit file as RINEX 3.04",
                       description="Write one RINEX 3.04 observation file per antenna of FILE.h5, and copy the "
                                   "RINEX navigation files its scenario used, so RTKLIB and other tools can "
                                   "process the simulated data.")
    p.add_argument("file", help="simkit HDF5 file with a /gnss group")
    p.add_argument("-o", "--out", default=".", help="output folder, created if missing (default: the current folder)")
    p.add_argument("--name", default=None, help="file name stem (default: the scenario name)")
    return p


def run(args) -> int:
    import tomllib

    from .. import open as open_dataset
    from ..errors import DataFileError
    from ..gnss.rinex import export

    from ..io import has
    from ..io.output import check_name, check_output

    out = check_output(args.out, [args.file], option="-o", folder=True, parents=True)
    check_name("--name", args.name)
    with open_dataset(args.file) as ds:
        if not has(ds, "gnss", "t"):
            raise DataFileError(args.file, "no /gnss group: the scenario has no [gnss] section")
        if not has(ds, "gnss_truth", "receiver_clock"):  # the time tags are receiver time: true time + clock
            raise DataFileError(args.file, "no /gnss/truth/receiver_clock: the RINEX export needs a simulated file "
                                           "(an imported file's observations are its RINEX file's)")
        try:
            scenario = tomllib.loads(ds.attrs["scenario_toml"])
        except (KeyError, tomllib.TOMLDecodeError) as exc:
            raise DataFileError(args.file, f"unreadable scenario_toml attribute ({exc})") from exc
        sources = [c.get("source", "") for c in scenario.get("gnss", {}).get("constellation", [])]
        name = args.name or ds.scenario_name
        gnss = {path[len("gnss/"):]: arr for path, arr in ds.datasets() if path.startswith("gnss/")}
        out.mkdir(parents=True, exist_ok=True)
        paths = export(gnss, int(ds.attrs["start_gps_week"]), float(ds.attrs["start_gps_sow"]), out, sources, name)
    for p in paths:
        print(p)
    skipped = [s for s in sources if s.startswith("nominal:")]
    if skipped:
        print(f"note: {', '.join(skipped)} have no navigation file to copy")
    return 0
