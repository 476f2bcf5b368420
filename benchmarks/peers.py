"""Where the benchmarks find gnss-ins-sim (github.com/Aceinna/gnss-ins-sim, not on PyPI): the project's shared
peers folder next to the checkout, or a path given on the command line."""
from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CANDIDATES = [p / "shared" / "peers" / "gnss-ins-sim" for p in (ROOT.parent, ROOT.parent.parent)]


def gnss_ins_sim(path: str | None = None):
    """gnss-ins-sim's ``pathgen`` module, or None when no checkout is found."""
    for p in ([Path(path)] if path else CANDIDATES):
        if (p / "gnss_ins_sim" / "pathgen" / "pathgen.py").is_file():
            sys.path.insert(0, str(p))
            from gnss_ins_sim.pathgen import pathgen

            return pathgen
    return None
