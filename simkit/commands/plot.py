"""``simkit plot FILE.h5 [--out DIR]``: overview figures of a simkit file as PNGs (needs the ``plot`` extra)."""
from __future__ import annotations

import sys
from pathlib import Path

from ..errors import ScenarioError, SimkitError


def add_parser(sub):
    p = sub.add_parser("plot", help="overview figures of a file: trajectory, sky, DOPs, Allan, observations, "
                                    "solutions vs truth",
                       description="Write PNG figures: trajectory map and altitude, sky plot, tracked satellites "
                                   "and DOPs, IMU Allan deviation, observation errors, and each /solutions group "
                                   "against the truth with +-3 sigma bounds. Needs matplotlib (the 'plot' extra).")
    p.add_argument("file", help="simkit HDF5 file")
    p.add_argument("--out", metavar="DIR", default="plots", help="output directory (created; default ./plots)")
    return p


def run(args) -> int:
    from tqdm import tqdm

    from ..io import check_output, open_dataset, solution_names
    from ..plots import FIGURES, file_figures, require_matplotlib, staged_directory

    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise ScenarioError("--out", f"{args.out} exists and is not a directory")
    if not out.parent.is_dir():
        raise ScenarioError("--out", f"{args.out}: directory {str(out.parent)!r} does not exist")
    check_output(out, [args.file], option="--out", folder=True)
    require_matplotlib("simkit plot")
    open_dataset(args.file).close()
    total = len(FIGURES) + len(solution_names(args.file))
    with staged_directory(out) as tmp, tqdm(total=total, desc="plot", unit="figure", leave=False) as bar:
        paths = [p.relative_to(tmp) for p in file_figures(args.file, tmp, bar,
                                                            on_skip=lambda line: bar.write(line, file=sys.stderr))]
        if not paths:  # raised inside the block: no empty folder is left
            raise SimkitError(f"{args.file}: no figure drawn: the overview figures need /truth (the Allan "
                              f"figure /imu), a solution's figures /truth or /reference to score it against")
    for p in paths:
        print(out / p)
    return 0
