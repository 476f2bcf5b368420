"""Shared check for the bad-input batteries: one clean error line, exit 2, no traceback, nothing left on disk."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def run_cli(args: list[str], cwd: Path, stdin: str | None = None, timeout: float = 120.0):
    """Run ``python -m simkit ARGS`` in ``cwd`` with this checkout's package first on the path."""
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return subprocess.run([sys.executable, "-m", "simkit", *args], cwd=cwd, env=env, input=stdin,
                          capture_output=True, text=True, timeout=timeout)


def snapshot(folder: Path) -> set[str]:
    """Every path under ``folder`` (hidden temp files included)."""
    return {str(p.relative_to(folder)) for p in folder.rglob("*")}


def assert_clean_error(args: list[str], cwd: Path, expect: str | None = None, stdin: str | None = None):
    """``simkit ARGS`` fails with exit 2, exactly one line on stderr (containing ``expect`` if given), no
    traceback, and leaves no new file under ``cwd``."""
    before = snapshot(cwd)
    proc = run_cli(args, cwd, stdin=stdin)
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert proc.returncode == 2, f"exit {proc.returncode} for {args}: {proc.stderr}"
    assert "Traceback" not in proc.stderr, proc.stderr
    assert len(lines) == 1, f"expected one error line for {args}, got: {proc.stderr}"
    if expect is not None:
        assert expect in lines[0], f"{expect!r} not in {lines[0]!r}"
    left = snapshot(cwd) - before
    assert not left, f"{args} left {sorted(left)}"
    return lines[0]
