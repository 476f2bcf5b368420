"""Reading data files as text lines: plain or gzip (detected from the magic bytes, not the name)."""
from __future__ import annotations

import gzip
from pathlib import Path

from ..errors import DataFileError


def read_bytes(path) -> bytes:
    """The content of a file, gunzipped when it is gzip data (whatever its name)."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise DataFileError(path, f"cannot read: {exc.strerror or exc}") from None
    if raw[:2] == b"\x1f\x8b":
        try:
            raw = gzip.decompress(raw)
        except (OSError, EOFError) as exc:
            raise DataFileError(path, f"corrupt or truncated gzip data ({exc})") from None
    return raw


def lines_of(raw: bytes) -> list[str]:
    """Text lines of file content (Latin-1, so any byte decodes), without line ends."""
    return raw.decode("latin-1").splitlines()



def number(text: str, path, line: int, what: str, blank=0.0) -> float:
    """One Fortran-style number (D or E exponent); ``blank`` when the field is empty (None: empty is an error)."""
    s = text.strip()
    if not s:
        if blank is None:
            raise DataFileError(path, f"missing {what}", line)
        return blank
    try:
        return float(s.replace("D", "E").replace("d", "e"))
    except ValueError:
        raise DataFileError(path, f"expected a number for {what}, found {s!r}", line) from None
