"""Exceptions for bad input: each carries one line naming the file, the key or line, and what was expected.

Every stage's bad-input error derives from :class:`InputError` (a ``ValueError``): the CLI prints ``str(error)``
on one line and exits 2 for any of them, never with a traceback. Other :class:`SimkitError` exit with their
:attr:`~SimkitError.exit_code`.
"""


class SimkitError(Exception):
    """Base class of every user-facing simkit error."""

    exit_code = 1


class InputError(SimkitError, ValueError):
    """Bad input to any stage (an argument, a key, a file's content): CLI exit 2.

    ``InputError(what, message)`` reads "what: message", ``what`` naming the argument, key or file, the message
    what was found and what was expected; ``InputError(text)`` takes a line already composed.
    """

    exit_code = 2

    def __init__(self, what, message: str | None = None):
        if message is None:
            super().__init__(str(what))
            return
        self.what, self.message = str(what), message
        super().__init__(f"{self.what}: {message}")


class ScenarioError(InputError):
    """A scenario key is unknown, missing, of the wrong type or out of range.

    ``key`` is the dotted path (``trajectory.segment[3].duration_s``); ``source`` the file, once known.
    """

    def __init__(self, key: str, message: str, source: str | None = None):
        self.key, self.message, self.source = key, message, source
        super().__init__(self._text())

    def _text(self) -> str:
        where = f"{self.source}: " if self.source else ""
        return f"{where}{self.key}: {self.message}" if self.key else f"{where}{self.message}"

    def with_source(self, source: str) -> "ScenarioError":
        return ScenarioError(self.key, self.message, source)


class DataFileError(InputError):
    """A data file (almanac, RINEX, TLE, HDF5) is malformed: names the file and the line or record."""

    def __init__(self, path, message: str, line: int | None = None):
        self.path, self.message, self.line = str(path), message, line
        where = f"{self.path}:{line}" if line is not None else self.path
        super().__init__(f"{where}: {message}")


class OutputError(InputError):
    """An output cannot be written where asked (missing folder, read-only place, a directory, the input itself),
    or would not fit: found before any work is done (the ``-o`` argument is bad input)."""

    def __init__(self, path, message: str):
        self.path, self.message = str(path), message
        super().__init__(f"{self.path}: {message}")
