"""The one error the ambiguity solver raises for bad input."""
from __future__ import annotations

from ..errors import InputError


class AmbiguityInputError(InputError):
    """An ambiguity problem is malformed: wrong shape, non-finite, non-symmetric or not positive definite.

    ``what`` names the argument (``"Q"``, ``"a_hat"``, ``"Q[3]"`` for epoch 3 of a batch, ...); the message says
    what was found and what was expected.
    """
