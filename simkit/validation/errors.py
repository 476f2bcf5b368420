"""Bad input to the validation stage: one line naming the argument (or file and key) and what was expected."""
from ..errors import InputError


class ValidationInputError(InputError):
    """An argument of :mod:`simkit.validation` has the wrong shape, is not finite, or names nothing usable."""
