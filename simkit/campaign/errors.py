"""The campaign package's bad-input error."""
from __future__ import annotations

from ..errors import SimkitError


class CampaignInputError(SimkitError, ValueError):
    """A campaign argument is malformed or cannot be honoured: ``what`` names the argument (``--grid``,
    ``--runs``, ``--scheduler``, ``-o``, a metric name), the message what was found and what was expected."""

    exit_code = 2

    def __init__(self, what: str, message: str):
        self.what, self.message = what, message
        super().__init__(f"{what}: {message}")
