"""Writing a file so that its final name only ever holds a complete file.

Everything is written under a hidden temporary name in the destination folder, ``.<name>.tmp-<pid>``, and renamed
over the final name when complete (``os.replace`` is atomic within a folder); on failure the temporary file is
removed. The pid in the name lets a later writer recognise and remove the leftovers of a killed one.
"""
from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path


def temporary_name(path, pid: int | None = None) -> Path:
    """Where ``path`` is written until it is complete: a hidden name with the writer's process id."""
    path = Path(path)
    return path.with_name(f".{path.name}.tmp-{os.getpid() if pid is None else pid}")


@contextmanager
def atomic_path(path):
    """Yield the temporary path to write ``path`` at; rename it to ``path`` when the block ends without error,
    remove it otherwise."""
    path = Path(path)
    tmp = temporary_name(path)
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


@contextmanager
def atomic_open(path, mode: str = "w", **kwargs):
    """``open(path, mode)`` through :func:`atomic_path`: readers never see a partial file."""
    with atomic_path(path) as tmp, open(tmp, mode, **kwargs) as f:
        yield f


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's live process
        return True
    return True


def remove_stale_temporaries(path) -> list[Path]:
    """Remove the temporary files of ``path`` left by writers that died (SIGKILL, power loss); returns them."""
    path = Path(path)
    removed = []
    for tmp in path.parent.glob(f".{path.name}.tmp-*"):
        pid = tmp.name.rsplit("-", 1)[-1]
        if pid.isdigit() and int(pid) != os.getpid() and not _pid_alive(int(pid)):
            tmp.unlink(missing_ok=True)
            removed.append(tmp)
    return removed
