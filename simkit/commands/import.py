"""``simkit import OBS [--nav NAV ...] [-o real.h5] [--reference X,Y,Z | --reference-file F]``: a real receiver's
RINEX observations as a simkit file (no /truth; /reference when a position is known). See docs/real_data.md."""
from __future__ import annotations

import sys
from pathlib import Path


def add_parser(sub):
    p = sub.add_parser("import", help="import a real RINEX observation file (with broadcast navigation) as a "
                                      "simkit file",
                       description="Read a RINEX 2.10/2.11, 3.0x or 4.00 observation file (plain, gzip or "
                                   "Hatanaka .crx) and its broadcast navigation files, and write a simkit HDF5 file "
                                   "of the same layout as a simulated one, without /truth: /reference holds the "
                                   "header's APPROX POSITION (or the given reference). Codes and systems simkit "
                                   "does not know are counted and reported.")
    p.add_argument("obs", help="RINEX observation file")
    p.add_argument("--nav", action="append", default=[], metavar="NAV",
                   help="RINEX 2/3/4 navigation file (repeatable): satellite orbits and clocks, Klobuchar (a path, or the name of a bundled one, as for simkit sky)")
    p.add_argument("-o", "--out", default=None, help="output file (default: OBS name with .h5, here)")
    p.add_argument("--reference", metavar="X,Y,Z", help="reference antenna position, m ECEF")
    p.add_argument("--reference-file", metavar="F", help="file holding the reference position X Y Z, m ECEF")
    p.add_argument("-q", "--quiet", action="store_true", help="no report on stdout")
    return p


def default_out(obs) -> Path:
    name = Path(obs).name
    for suffix in (".gz", ".crx", ".rnx", ".obs"):
        if name.lower().endswith(suffix):
            name = name[: -len(suffix)]
    return Path(name + ".h5")


def run(args) -> int:
    from ..io.output import check_output
    from ..realdata import importer

    obs, navs = importer.input_files(args.obs, args.nav)
    reference, source = importer.parse_reference(args.reference, args.reference_file)
    out = check_output(args.out or default_out(args.obs), [obs, *navs, args.reference_file], option="-o")
    imported = importer.import_rinex(obs, navs, reference, source)
    importer.write(out, imported)
    if not args.quiet:
        sys.stdout.write(importer.describe(imported, out))
    return 0
