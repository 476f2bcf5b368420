"""Where the benchmarks find gnss-ins-sim (github.com/Aceinna/gnss-ins-sim, not on PyPI): a checkout given on the
command line, or named by the ``GNSS_INS_SIM`` environment variable."""
from __future__ import annotations

import os
import sys
from pathlib import Path

CANDIDATES = [Path(os.environ["GNSS_INS_SIM"])] if os.environ.get("GNSS_INS_SIM") else []


def gnss_ins_sim(path: str | None = None):
    """gnss-ins-sim's ``pathgen`` module, or None when no checkout is found."""
    for p in ([Path(path)] if path else CANDIDATES):
        if (p / "gnss_ins_sim" / "pathgen" / "pathgen.py").is_file():
            sys.path.insert(0, str(p))
            from gnss_ins_sim.pathgen import pathgen

            return pathgen
    return None
