"""Exceptions for bad input: each carries one line naming the file, the key or line, and what was expected.

The CLI prints ``str(error)`` and exits with :attr:`SimkitError.exit_code`; it never shows a traceback for them.
"""


class SimkitError(Exception):
    """Base class of every user-facing simkit error."""

    exit_code = 1


class ScenarioError(SimkitError):
    """A scenario key is unknown, missing, of the wrong type or out of range.

    ``key`` is the dotted path (``trajectory.segment[3].duration_s``); ``source`` the file, once known.
    """

    exit_code = 2

    def __init__(self, key: str, message: str, source: str | None = None):
        self.key, self.message, self.source = key, message, source
        super().__init__(self._text())

    def _text(self) -> str:
        where = f"{self.source}: " if self.source else ""
        return f"{where}{self.key}: {self.message}" if self.key else f"{where}{self.message}"

    def with_source(self, source: str) -> "ScenarioError":
        return ScenarioError(self.key, self.message, source)


class DataFileError(SimkitError):
    """A data file (almanac, RINEX, TLE, HDF5) is malformed: names the file and the line or record."""

    exit_code = 2

    def __init__(self, path, message: str, line: int | None = None):
        self.path, self.message, self.line = str(path), message, line
        where = f"{self.path}:{line}" if line is not None else self.path
        super().__init__(f"{where}: {message}")


class OutputError(SimkitError):
    """An output cannot be written where asked (missing folder, read-only place, a directory, the input itself),
    or would not fit: found before any work is done."""

    exit_code = 2

    def __init__(self, path, message: str):
        self.path, self.message = str(path), message
        super().__init__(f"{self.path}: {message}")
