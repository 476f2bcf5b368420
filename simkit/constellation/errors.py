"""The errors the constellation package raises for bad input (malformed files raise ``DataFileError``)."""
from __future__ import annotations

from ..errors import InputError


class ConstellationInputError(InputError):
    """An argument is malformed: ``what`` names it (``"gps_week"``, ...); the message says what was found and
    what was expected."""


class NoStateError(ConstellationInputError):
    """No satellite of a source has a state at any of the requested times: the message names the source, the
    times asked for and the span the source covers (``span``: ((week, sow), (week, sow)) or None)."""

    def __init__(self, source: str, message: str, span=None):
        self.span = span
        super().__init__(source, message)
