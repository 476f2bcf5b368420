"""Bad input to the estimators: one error class naming the argument (or key) and what was expected."""
from __future__ import annotations

from ..errors import InputError


class EstimatorInputError(InputError):
    """An estimator argument, ``--set estimator.*`` key or input file content is not what the filter needs."""
