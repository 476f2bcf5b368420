"""The ``simkit`` command line: one sub-command per module in :mod:`simkit.commands`.

Bad input ends with one line on stderr (which file, which key or line, what was expected) and exit code 2,
never a traceback. SIGTERM and SIGHUP stop a command like Ctrl-C does (partial outputs are removed); a closed
output pipe (``simkit inspect f.h5 | head -1``) ends the command quietly.
"""
from __future__ import annotations

import argparse
import atexit
import importlib
import os
import signal
import sys
import threading

from .commands import silence_stdout
from .errors import InputError, SimkitError
from .version import __version__

# simkit's matrices are small (64 x 64 frames, 15-state filters): OpenBLAS's worker threads only spin beside
# simkit's own (the truth lane, the compression pool), 0.1 s of CPU in a 0.7 s truth + IMU run, none of the wall
BLAS_THREAD_VARS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")

COMMANDS = ("run", "inspect", "solve", "validate", "score", "plot", "regress", "campaign", "allan", "sky", "rinex",
            "export", "import", "twin", "compile")


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (exit 2) instead of the usage block."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="simkit", description="Multi-antenna GNSS/INS simulation toolkit.")
    parser.add_argument("--version", action="version", version=f"simkit {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True, parser_class=_Parser)
    for name in COMMANDS:
        module = importlib.import_module(f"simkit.commands.{name}")
        module.add_parser(sub).set_defaults(_run=module.run)
    return parser


def _interrupt(signum, frame):
    raise KeyboardInterrupt(signal.Signals(signum).name)


def _close_bars() -> None:
    """Close every progress bar still drawn (a command stopped inside one): the error line then starts on a clean
    line instead of being appended to the bar's."""
    tqdm = sys.modules.get("tqdm")
    for bar in list(getattr(getattr(tqdm, "tqdm", None), "_instances", ())):
        bar.close()


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    previous = {sig: signal.signal(sig, _interrupt) for sig in (signal.SIGTERM, signal.SIGHUP)}
    try:
        return int(args._run(args) or 0)
    except SimkitError as exc:
        _close_bars()
        print(f"simkit {args.command}: error: {exc}", file=sys.stderr)
        return 2 if isinstance(exc, InputError) else exc.exit_code
    except KeyboardInterrupt as exc:
        _close_bars()
        print(f"simkit {args.command}: interrupted{f' ({exc})' if str(exc) else ''}", file=sys.stderr)
        return 130
    except BrokenPipeError:
        silence_stdout()  # the reader went away (| head): stop quietly
        return 0
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def one_blas_thread() -> bool:
    """Make numpy's BLAS single-threaded in this process when the user did not choose (none of
    :data:`BLAS_THREAD_VARS` set) and numpy is not loaded yet (the setting is read when it loads). The command's
    child processes (campaign workers) inherit it. Returns whether it was set."""
    if "numpy" in sys.modules or any(v in os.environ for v in BLAS_THREAD_VARS):
        return False
    os.environ["OPENBLAS_NUM_THREADS"] = "1"
    return True


def console(argv=None) -> int:
    """The ``simkit`` command and ``python -m simkit``: BLAS on one thread (:func:`one_blas_thread`), :func:`main`,
    then the process ends at once. The work is done by then (outputs closed and renamed): the standard streams are
    flushed and the ``atexit`` handlers run, but the interpreter's teardown of every module and object (30-40 ms
    after a truth + IMU run, more than the file's close) is skipped, as is the kernel's wait for it. While another
    thread still runs (it would be joined at a normal exit) the exit is the normal one."""
    one_blas_thread()
    code = main(argv)
    if threading.active_count() > 1:
        return code
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed or broken pipe: nothing more can reach the reader
            pass
    atexit._run_exitfuncs()
    os._exit(code)


if __name__ == "__main__":
    sys.exit(console())
