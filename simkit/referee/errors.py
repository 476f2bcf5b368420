"""Bad input to the referee: one line naming the file, argument or key and what was expected (CLI exit 2)."""
from __future__ import annotations

from ..errors import InputError


class RefereeInputError(InputError):
    """An estimate, a spec or an argument the referee cannot use: ``where`` (file, argument or key): message."""

    def __init__(self, where, message: str):
        self.where = str(where)
        super().__init__(where, message)
