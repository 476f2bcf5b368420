"""The one check of an output path, before any work, for every command (``run -o``, ``score --json/--report``,
``validate --json/--report``, ``allan --json/--plot``, ``plot --out``, ``sky --plot``, ``campaign -o``,
``rinex -o``): the folder exists and is writable, a file target is not a directory (a folder target not a file),
not an input of the same command, not read-only, and the estimated size fits on the disk. An output never
replaces an input; ``simkit run`` replaces only a simkit file without solutions (else ``--force``).
"""
from __future__ import annotations

import os
import shutil
from pathlib import Path

from ..errors import OutputError
from ..atomic import temporary_name


def check_output(out, inputs=(), estimated_bytes: int = 0, force: bool = False, option: str | None = None,
                 folder: bool = False, simkit_only: bool = False, parents: bool = False) -> Path:
    """``out`` as a Path once it is known that it can be written; :class:`OutputError` (one line naming
    ``option`` and the path) otherwise.

    ``inputs``: paths the command reads (the output must not be one). ``folder``: ``out`` is a folder the command
    creates or fills (``--report DIR``); else a file. ``estimated_bytes``: an upper bound of the file size, refused
    above the free space of the folder unless ``force``. ``simkit_only``: an existing file is replaced only when it
    is a simkit file holding no /solutions (one ``simkit run`` wrote), unless ``force``. ``parents``: the command
    creates missing parent folders too (``rinex -o a/b``): the nearest existing one must be a writable folder.
    """
    out = Path(out)
    where = f"{option}: {out}" if option else str(out)
    parent = out.parent if str(out.parent) else Path(".")
    if parents:  # the command creates the missing folders: the nearest existing one decides
        parent = next(p for p in out.absolute().parents if p.exists())
    if folder:
        if out.exists() and not out.is_dir():
            raise OutputError(where, "exists and is not a folder; expected a folder to write into")
    elif out.is_dir():
        raise OutputError(where, "is a directory, expected an output file name")
    if not parent.is_dir():
        raise OutputError(where, f"{parent} is not a folder" if parent.exists() else f"folder {parent} does not exist")
    _not_an_input(out, inputs, where)
    if folder:
        if not os.access(out if out.is_dir() else parent, os.W_OK):
            raise OutputError(where, "folder is not writable")
        return out
    _probe(parent, out, where)
    _replaceable(out, where)
    if simkit_only and not force:
        _simkit_run_output(out, where)
    free = shutil.disk_usage(parent).free
    if estimated_bytes > free and not force:
        raise OutputError(where, f"needs up to {estimated_bytes / 2**30:.1f} GiB, the disk has "
                          f"{free / 2**30:.1f} GiB free (--force to try anyway)")
    return out


def check_outputs(outputs, inputs) -> None:
    """:func:`check_output` of each ``(option, path or None, is_folder)`` of a command against its ``inputs``."""
    for option, out, folder in outputs:
        if out is not None:
            check_output(out, inputs, option=option, folder=folder)


def _not_an_input(out: Path, inputs, where: str) -> None:
    if not out.exists():
        return
    for src in inputs:
        if src is not None and Path(src).exists() and out.samefile(src):
            raise OutputError(where, "is an input of this command; choose another output name")


def _replaceable(out: Path, where: str) -> None:
    if out.exists():
        try:
            with open(out, "ab"):
                pass
        except OSError as exc:
            raise OutputError(where, f"cannot be replaced ({exc.strerror.lower()})") from None


def _simkit_run_output(out: Path, where: str) -> None:
    """An existing ``out`` that is not a simkit file without /solutions (a README, a CSV, a foreign HDF5 file,
    solved results) is refused."""
    if not out.is_file():
        return
    import h5py

    why = "is not a simkit file"
    if h5py.is_hdf5(out):
        try:
            with h5py.File(out, "r") as f:
                if "schema_version" in f.attrs and "scenario_toml" in f.attrs:
                    why = "holds /solutions (simkit solve results)" if "solutions" in f else ""
        except OSError:
            pass
    if why:
        raise OutputError(where, f"exists and {why}; refusing to replace it (another name, or --force)")


def check_name(option: str, name: str | None) -> None:
    """A file-name stem given on its own (``rinex --name``): no folder part, not '.' or '..', not hidden."""
    if name is not None and (not name or Path(name).name != name or name.startswith(".") or os.sep in name
                             or "/" in name):
        raise OutputError(option, f"expected a plain file name (no folder, not starting with '.'), got {name!r}")


def _probe(folder: Path, out: Path, where: str) -> None:
    """Create and remove the temporary file the writer will use: proves the folder is writable."""
    tmp = temporary_name(out)
    try:
        fd = os.open(tmp, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
    except FileExistsError:
        return
    except OSError as exc:
        raise OutputError(where, f"cannot write in {folder} ({exc.strerror.lower()})") from None
    os.close(fd)
    os.unlink(tmp)
