"""``simkit validate SCENARIO|FILE.h5``: observability claims of Wang 2018 (C1-C7) for every satellite count.

A scenario is simulated first, geometry only (trajectory and sky, no file written); a simkit file is read
(/gnss/sat_pos_ecef, antenna positions, attitude). Exit 0 when the mathematical claims C1-C5 hold on every
non-degenerate epoch, 1 when one fails, 2 for bad input (one line on stderr). Argument glue and reports around
:func:`simkit.api.validate`.
"""
from __future__ import annotations

import shlex
import sys

from ..atomic import atomic_open
from ..io.output import check_output


def add_parser(sub):
    p = sub.add_parser("validate", help="observability validation (Gramian, ATDOP, observable degree, rank)",
                       description="Check Wang 2018's observability claims C1-C7 for the dual- and three-antenna "
                                   "configurations, every satellite count from 2 to all visible, at every epoch "
                                   "of a scenario (geometry only) or a simkit HDF5 file.")
    p.add_argument("input", help="scenario TOML (file or bundled name) or simkit HDF5 file")
    p.add_argument("--json", metavar="OUT.json", help="write the machine-readable summary here")
    p.add_argument("--report", metavar="DIR", help="write report.md and PNG figures into this folder (created)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scenario key (scenario input only), e.g. --set scenario.duration_s=3600")
    p.add_argument("--systems", metavar="LETTERS",
                   help="only satellites of these systems, comma-separated RINEX letters (e.g. C for BDS)")
    p.add_argument("--weighting", choices=("dd", "identity"), default="dd",
                   help="R: 'dd' equally weighted undifferenced phases (correlated DDs, default) or 'identity'")
    p.add_argument("--random", type=int, default=1, metavar="N",
                   help="random satellite orderings per epoch besides highest-elevation-first (default 1)")
    p.add_argument("--random-stride", type=int, default=10, metavar="N",
                   help="draw the random orderings at every N-th epoch (default 10; 1 = every epoch)")
    p.add_argument("--seed", type=int, default=0, help="seed of the random subsets (default 0)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


def run(args) -> int:
    from ..api import check_validate, validate

    check_validate(args.random, args.random_stride)
    report = _check_outputs(args)
    v = validate(args.input, args.set, systems=args.systems, weighting=args.weighting, n_random=args.random,
                 random_stride=args.random_stride, seed=args.seed, progress=not args.no_progress)
    _write(args, v, report)
    claims = v.summary["claims"]
    for name, c in claims.items():
        verdict = ("held" if c["held"] else f"FAILED ({c['failed']} of {c['checked']})") \
            if c["type"] == "mathematical" else f"held in {100 * (c['fraction'] or 0):.2f} %"
        print(f"{name}: {verdict}  [{c['statement']}]")
    print(f"{v.summary['epochs']} epochs, {v.summary['visible']['min']}-{v.summary['visible']['max']} visible; "
          f"validation {v.summary['elapsed_s']} s")
    return 1 if v.mathematical_failure else 0


def _check_outputs(args):
    """Before any work: the JSON and report paths (:func:`check_output`)."""
    inputs = [args.input]
    if args.json:
        check_output(args.json, inputs, option="--json")
    if args.report:
        rep = check_output(args.report, inputs, option="--report", folder=True)
        from ..plots import require_matplotlib

        require_matplotlib("--report")
        return rep
    return None


def _write(args, v, report):
    from ..validation import report as rp

    if args.json:
        rp.write_json(args.json, v.summary)
    if report is not None:
        report.mkdir(exist_ok=True)
        from ..plots import validation_figures

        figures = validation_figures(report, v)
        command = "simkit validate " + " ".join(shlex.quote(a) for a in sys.argv[2:]) if sys.argv[1:2] == \
            ["validate"] else ""
        text = rp.markdown(v, figures, command).encode()
        with atomic_open(report / "report.md", "wb") as f:
            f.write(text)
