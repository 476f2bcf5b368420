"""The bundled LAMBDA ambiguity solver: decorrelation, integer least squares, success rates, validation,
partial fixing and the baseline-constrained (attitude) solvers. See docs/ambiguity.md."""
from .constrained import ConstrainedResult, attitude_constrained_ils, baseline_constrained_ils
from .decorrelation import Decorrelation, decorrelate, ltdl
from .enumeration import enumerate_ils
from .errors import AmbiguityInputError
from .estimators import bootstrapping, rounding
from .search import DEFAULT_MAX_NODES, ILSBatchResult, ILSResult, ils, ils_batch
from .success import (adop, adop_success_rate, adop_upper_bound, bootstrap_success_rate, ils_success_bounds,
                      monte_carlo_success_rate, monte_carlo_success_rates, pullin_lower_bound, pullin_upper_bound,
                      success_rate_bounds)
from .validation import (DEFAULT_RATIO_THRESHOLD, PartialFix, ffrt, ffrt_threshold, ffrt_thresholds, partial_fix,
                         ratio_test)

__all__ = [
    "AmbiguityInputError", "ConstrainedResult", "DEFAULT_MAX_NODES", "DEFAULT_RATIO_THRESHOLD", "Decorrelation", "ILSBatchResult",
    "ILSResult", "PartialFix", "adop", "adop_success_rate", "adop_upper_bound", "attitude_constrained_ils",
    "baseline_constrained_ils", "bootstrap_success_rate",
    "bootstrapping", "decorrelate", "enumerate_ils", "ffrt", "ffrt_threshold", "ffrt_thresholds", "ils", "ils_batch",
    "ils_success_bounds",
    "ltdl", "monte_carlo_success_rate", "monte_carlo_success_rates", "partial_fix", "pullin_lower_bound",
    "pullin_upper_bound", "ratio_test", "rounding", "success_rate_bounds",
]
