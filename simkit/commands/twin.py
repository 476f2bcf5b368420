"""``simkit twin OBS --nav NAV [-o DIR] [--fit]``: simulate the receiver of a real RINEX file and compare the two
(DIR/real.h5, twin.h5, fidelity.json, report.md, figures; with --fit also twin_fit.h5 and fitted.toml).
See docs/real_data.md."""
from __future__ import annotations

import sys


def add_parser(sub):
    p = sub.add_parser("twin", help="simulate the twin of a real receiver file and measure their differences",
                       description="Import a RINEX observation file, simulate the same static receiver (reference "
                                   "position, epochs, signals, broadcast sky, inferred elevation mask) and compare "
                                   "tracking, C/N0, code noise and multipath, carrier and Doppler noise and slips; "
                                   "--fit estimates simkit's [gnss] error parameters from the real file.")
    p.add_argument("obs", help="RINEX observation file (2.1x, 3.0x, 4.00; plain, gzip or Hatanaka)")
    p.add_argument("--nav", action="append", default=[], metavar="NAV", required=True,
                   help="RINEX 2/3/4 navigation file (repeatable) (a path, or the name of a bundled one, as for simkit sky)")
    p.add_argument("-o", "--out", default="twin", help="output folder (created; default ./twin)")
    p.add_argument("--fit", action="store_true", help="fit the [gnss] error parameters and run the calibrated twin")
    p.add_argument("--reference", metavar="X,Y,Z", help="receiver position, m ECEF (default: the header's)")
    p.add_argument("--trajectory", metavar="LOG", help="a moving receiver: its path from a log (any [trajectory] "
                   "source: CSV, NMEA, GPX, KML, or a simkit file's /solutions, e.g. the real file's SPP)")
    p.add_argument("--trajectory-solution", metavar="NAME", help="the /solutions group of an .h5 --trajectory")
    p.add_argument("--seed", type=int, default=1, help="seed of the twin (default 1)")
    p.add_argument("--code-model", choices=("smooth", "bins"), default="smooth",
                   help="--fit's code-noise correction: a line in elevation per signal (default) or a factor per bin")
    p.add_argument("--realisations", type=int, default=4, metavar="N",
                   help="twins (seeds) pooled for the twin's code noise and C/N0 in the checks (default 4)")
    p.add_argument("--no-shadowing", action="store_true",
                   help="--fit of a moving receiver without the street-shadowing channel ([gnss.shadowing])")
    p.add_argument("--no-plots", action="store_true", help="no figures (they need the 'plot' extra)")
    return p


def run(args) -> int:
    from ..io.output import check_output
    from ..realdata import importer, twin

    obs, navs = importer.input_files(args.obs, args.nav, [args.trajectory])
    out = check_output(args.out, [obs, *navs, *([args.trajectory] if args.trajectory else [])], option="-o",
                       folder=True, parents=True)
    if not args.no_plots:
        from ..plots import require_matplotlib

        require_matplotlib("twin (or --no-plots)")
    reference, source = importer.parse_reference(args.reference, None)
    fid = twin.run_twin(obs, navs, out, fit=args.fit, seed=args.seed, reference=reference, progress=True,
                        reference_source=source, trajectory=args.trajectory,
                        trajectory_solution=args.trajectory_solution, code_model=args.code_model,
                        realisations=args.realisations, shadowing=not args.no_shadowing)
    figures = []
    if not args.no_plots:
        from ..plots import twin_figures

        figures = twin_figures(fid, out)
    report = twin.report_markdown(fid, figures)
    (out / "report.md").write_text(report)
    sys.stdout.write(report)
    return 0
