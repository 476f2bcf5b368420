"""The test commands the README and docs quote run tests: each selects at least one test under the project's
pytest options (``-m 'not slow'`` by default), so a figure's "command" column reproduces something."""
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
QUOTED = re.compile(r"`(?:python -m )?(pytest [^`]*)`")


def quoted_commands() -> list[str]:
    """Every backticked ``pytest ...`` command of README.md and docs/*.md that names a test file."""
    found = set()
    for doc in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        found.update(c for c in QUOTED.findall(doc.read_text(encoding="utf-8")) if "tests/" in c)
    return sorted(found)


@pytest.mark.slow
@pytest.mark.parametrize("command", quoted_commands())
def test_a_quoted_test_command_selects_tests(command):
    """Regression: `pytest -s tests/test_gnss_doppler.py` ran no test (its only test is marked slow)."""
    args = [a for a in shlex.split(command)[1:] if a != "-s"]
    args = [str(p) for a in args for p in (sorted(ROOT.glob(a)) if "*" in a else [a])]  # as a shell expands them
    proc = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-p", "no:cacheprovider", *args],
                          cwd=ROOT, capture_output=True, text=True, timeout=300)
    selected = [ln for ln in proc.stdout.splitlines() if "::" in ln]
    assert proc.returncode == 0 and selected, f"{command} selects no test:\n{proc.stdout[-2000:]}{proc.stderr[-2000:]}"
