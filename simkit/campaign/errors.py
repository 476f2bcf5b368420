"""The campaign package's bad-input error."""
from __future__ import annotations

from ..errors import InputError


class CampaignInputError(InputError):
    """A campaign argument is malformed or cannot be honoured: ``what`` names the argument (``--grid``,
    ``--runs``, ``--scheduler``, ``-o``, a metric name), the message what was found and what was expected."""
