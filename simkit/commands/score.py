"""``simkit score FILE.h5 ESTIMATE``: errors of an estimate (a /solutions group or a CSV) against the truth.

Argument glue and reports around :func:`simkit.api.score`.

Every check on the arguments and inputs runs before any computing; bad input is one line on stderr and exit 2.
Exit code 1 when a spec is given and a check fails.
"""
from __future__ import annotations

import sys
from pathlib import Path

from ..errors import ScenarioError


def add_parser(sub):
    p = sub.add_parser("score", help="score an estimate (HDF5 /solutions or CSV) against the file's truth",
                       description="Align the estimate's epochs with the truth, convert frames and conventions, and "
                                   "report ENU position/velocity and pitch/roll/heading errors: RMS, max, 50/95/99 %"
                                   " percentiles, convergence time, NEES/NIS with chi-square bounds, and pass/fail "
                                   "against a TOML spec. Exit 1 when a spec check fails.")
    p.add_argument("file", help="simkit HDF5 file holding the truth")
    p.add_argument("estimate", help="a simkit HDF5 file with /solutions (the same file is fine) or a CSV "
                                    "(columns: docs/referee.md)")
    p.add_argument("--solution", metavar="NAME", help="which /solutions/NAME to score (needed when several)")
    p.add_argument("--point", metavar="POINT", help="for a CSV estimate: the point its position and velocity "
                                                    "belong to: imu (default), antenna:K (the file's antenna K) or "
                                                    "lever_b:[x,y,z] (body frame x right, y forward, z up, m)")
    p.add_argument("--spec", metavar="PASS.toml", help="thresholds for pass/fail (docs/referee.md)")
    p.add_argument("--json", metavar="OUT", help="write the scores as JSON")
    p.add_argument("--report", metavar="DIR", help="write report.md and error plots (needs the 'plot' extra) here")
    return p


def _check_outputs(args):
    if args.json:
        parent = Path(args.json).parent
        if not parent.is_dir():
            raise ScenarioError("--json", f"{args.json}: directory {str(parent)!r} does not exist")
        if Path(args.json).is_dir():
            raise ScenarioError("--json", f"{args.json} is a directory, expected a file name")
    if args.report:
        report = Path(args.report)
        if report.exists() and not report.is_dir():
            raise ScenarioError("--report", f"{args.report} exists and is not a directory")
        if not report.parent.is_dir():
            raise ScenarioError("--report", f"{args.report}: directory {str(report.parent)!r} does not exist")


def run(args) -> int:
    from .. import referee
    from ..api import score_labelled

    _check_outputs(args)
    from ..io.output import check_outputs  # an output never replaces an input

    check_outputs([("--json", args.json, False), ("--report", args.report, True)],
                  [args.file, args.estimate, args.spec])
    spec = referee.load_spec(args.spec) if args.spec else None
    if args.report:
        from ..plots import require_matplotlib

        require_matplotlib("--report")
    sc, label = score_labelled(args.file, args.estimate, spec, args.solution, args.point)
    markdown = referee.to_markdown(sc, label, args.file)
    sys.stdout.write(markdown)
    if args.json:
        Path(args.json).write_text(referee.to_json(sc, label))
    if args.report:
        from ..plots import score_figures, staged_directory

        with staged_directory(args.report) as out:
            (out / "report.md").write_text(markdown + "".join(f"\n![{p.stem}]({p.name})\n"
                                                              for p in score_figures(sc, out, label)))
    return 0 if sc.passed else 1
