"""CLI sub-commands: one module each, with ``add_parser(subparsers)`` and ``run(args) -> int``."""
import os
import sys


def silence_stdout() -> None:
    """The reader of stdout went away (``| head``): point stdout at os.devnull, so that neither later writes nor
    the interpreter's final flush raise BrokenPipeError. Commands that still have files to write carry on."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)
