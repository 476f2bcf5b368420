"""The ``simkit`` command line: one sub-command per module in :mod:`simkit.commands`.

Bad input ends with one line on stderr (which file, which key or line, what was expected) and a non-zero exit
code, never a traceback.
"""
from __future__ import annotations

import argparse
import importlib
import sys

from . import __version__
from .errors import SimkitError

COMMANDS = ("run", "inspect", "allan", "sky", "rinex")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="simkit", description="Multi-antenna GNSS/INS simulation toolkit.")
    parser.add_argument("--version", action="version", version=f"simkit {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        module = importlib.import_module(f"simkit.commands.{name}")
        module.add_parser(sub).set_defaults(_run=module.run)
    return parser


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return int(args._run(args) or 0)
    except SimkitError as exc:
        print(f"simkit {args.command}: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print(f"simkit {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
