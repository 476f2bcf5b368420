"""Where numba caches simkit's compiled kernels, so that a read-only install does not compile in every process.

numba looks for a cache directory per source file: ``$NUMBA_CACHE_DIR`` when set, else ``__pycache__`` next to
the source when writable, else the user's cache directory (``$XDG_CACHE_HOME/numba``, ``~/.cache/numba``). In a
container or a cluster image both of the last two can be read-only; numba then refuses every ``cache=True``
function at import ("no locator available"), and simkit could not even be imported. :func:`choose` runs once at
``import simkit``, before any kernel is defined: with ``$NUMBA_CACHE_DIR`` unset and neither directory writable,
it points numba at ``<temporary directory>/simkit-numba-<uid>`` (also exported, so that worker processes started
from this one share it). Compiled code is keyed by source, CPU and numba version, so a shared directory is safe.
"""
from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent


def writable(directory: Path) -> bool:
    """True when a file can be created in ``directory`` (created if missing), the test numba itself applies."""
    try:
        directory.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=directory):
            return True
    except OSError:
        return False


def user_cache_dir() -> Path:
    """numba's user-wide cache directory on this platform."""
    from numba.misc.appdirs import AppDirs

    return Path(AppDirs(appname="numba", appauthor=False).user_cache_dir)


def fallback_dir() -> Path:
    """The cache directory used when numba has none: per user, under the system's temporary directory."""
    uid = os.getuid() if hasattr(os, "getuid") else os.getlogin()
    return Path(tempfile.gettempdir()) / f"simkit-numba-{uid}"


def choose() -> Path | None:
    """Set numba's cache directory when it would have none (see the module docstring); returns the directory
    set, or None when numba's own choice stands."""
    if os.environ.get("NUMBA_CACHE_DIR") or writable(_PACKAGE / "__pycache__") or writable(user_cache_dir()):
        return None
    path = fallback_dir()
    if not writable(path):
        return None  # nowhere to write: numba then explains at the first kernel it cannot cache
    os.environ["NUMBA_CACHE_DIR"] = str(path)
    if "numba.core.config" in sys.modules:  # numba read its configuration at import: tell it too
        sys.modules["numba.core.config"].CACHE_DIR = str(path)
    return path
