"""Checks on an output path before any work: the folder exists and is writable, the target is not a directory,
not an input file, not read-only or immutable, and the estimated size fits on the disk."""
from __future__ import annotations

import os
import shutil
from pathlib import Path

from ..errors import OutputError
from ..atomic import temporary_name


def check_output(out, inputs=(), estimated_bytes: int = 0, force: bool = False) -> Path:
    """``out`` as a Path once it is known that a file can be written there; :class:`OutputError` otherwise.

    ``inputs``: files the run reads (the output must not overwrite one). ``estimated_bytes``: an upper bound of
    the file size, refused when above the free space of the folder unless ``force``.
    """
    out = Path(out)
    if out.is_dir():
        raise OutputError(out, "is a directory, expected an output file name")
    folder = out.parent if str(out.parent) else Path(".")
    if not folder.is_dir():
        raise OutputError(out, f"folder {folder} does not exist")
    for src in inputs:
        if src is not None and Path(src).is_file() and out.exists() and out.samefile(src):
            raise OutputError(out, "is an input of this run; choose another output name")
    _probe(folder, out)
    if out.exists():
        try:
            with open(out, "ab"):
                pass
        except OSError as exc:
            raise OutputError(out, f"cannot be replaced ({exc.strerror.lower()})") from None
    free = shutil.disk_usage(folder).free
    if estimated_bytes > free and not force:
        raise OutputError(out, f"needs up to {estimated_bytes / 2**30:.1f} GiB, the disk has {free / 2**30:.1f} GiB "
                          "free (--force to try anyway)")
    return out


def _probe(folder: Path, out: Path) -> None:
    """Create and remove the temporary file the writer will use: proves the folder is writable."""
    tmp = temporary_name(out)
    try:
        fd = os.open(tmp, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
    except FileExistsError:
        return
    except OSError as exc:
        raise OutputError(out, f"cannot write in {folder} ({exc.strerror.lower()})") from None
    os.close(fd)
    os.unlink(tmp)
