"""Shared check for the bad-input batteries: one clean error line, exit 2, no traceback, nothing left on disk.

The CLI runs in this process (``simkit.cli.main``: an unexpected exception fails the test with its traceback,
as a user would see one) unless ``isolated=True``, which runs ``python -m simkit`` in a child process, for what
needs a fresh interpreter (a shadowed module through PYTHONPATH, closed pipes, signals).
"""
from __future__ import annotations

import contextlib
import hashlib
import io
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@dataclass
class Completed:
    returncode: int
    stdout: str
    stderr: str


def run_cli(args: list[str], cwd: Path, stdin: str | None = None, timeout: float = 120.0,
            isolated: bool = False) -> Completed:
    """Run ``simkit ARGS`` in ``cwd``; returns exit code, stdout and stderr."""
    if isolated or stdin is not None:
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (env.get("PYTHONPATH"), str(ROOT)) if p)
        proc = subprocess.run([sys.executable, "-m", "simkit", *args], cwd=cwd, env=env, input=stdin,
                              capture_output=True, text=True, timeout=timeout)
        return Completed(proc.returncode, proc.stdout, proc.stderr)
    from simkit.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.chdir(cwd), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(list(args))
        except SystemExit as exc:  # argparse: --help, usage errors
            code = exc.code if isinstance(exc.code, int) else 1
    return Completed(int(code or 0), out.getvalue(), err.getvalue())


def digest(path: Path) -> str:
    """SHA-256 of a file's bytes: an input a failed command must leave exactly as it was."""
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def snapshot(folder: Path) -> set[str]:
    """Every path under ``folder`` (hidden temp files included)."""
    return {str(p.relative_to(folder)) for p in folder.rglob("*")}


def assert_clean_error(args: list[str], cwd: Path, expect: str | None = None, stdin: str | None = None,
                       isolated: bool = False):
    """``simkit ARGS`` fails with exit 2, exactly one line on stderr (containing ``expect`` if given), no
    traceback, and leaves no new file under ``cwd``."""
    before = snapshot(cwd)
    proc = run_cli(args, cwd, stdin=stdin, isolated=isolated)
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert proc.returncode == 2, f"exit {proc.returncode} for {args}: {proc.stderr}"
    assert "Traceback" not in proc.stderr, proc.stderr
    assert len(lines) == 1, f"expected one error line for {args}, got: {proc.stderr}"
    if expect is not None:
        assert expect in lines[0], f"{expect!r} not in {lines[0]!r}"
    left = snapshot(cwd) - before
    assert not left, f"{args} left {sorted(left)}"
    return lines[0]
