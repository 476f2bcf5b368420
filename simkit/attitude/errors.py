"""The attitude package's bad-input error: names the argument, key or file and what was expected."""
from __future__ import annotations

from ..errors import InputError


class AttitudeInputError(InputError):
    """Bad input to :mod:`simkit.attitude` (a wrong shape, an unknown parameter, a file without what is needed).

    ``what`` is the argument, parameter key or dataset path; the message says what was found and expected.
    """
