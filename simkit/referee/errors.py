"""Bad input to the referee: one line naming the file, argument or key and what was expected (CLI exit 2)."""
from __future__ import annotations

from ..errors import SimkitError


class RefereeInputError(SimkitError, ValueError):
    """An estimate, a spec or an argument the referee cannot use: ``where`` (file, argument or key): message."""

    exit_code = 2

    def __init__(self, where, message: str):
        self.where, self.message = str(where), message
        super().__init__(f"{self.where}: {message}")
