"""Observability validation of multi-antenna GNSS attitude (Wang 2018): Gramian, ATDOP, observable degree, rank
for every satellite count, claims C1-C7. See docs/validation.md."""
from .errors import ValidationInputError
from .gramian import accumulated_gramian, design_matrix, gramian, gramian_from_scatter, los_scatter, skew
from .observability import (NULL_COMPONENT_TOL, RANK_RTOL, atdop, atdop_from_svd, observable_degree,
                            observable_degree_from_svd, rank, svd)

__all__ = [
    "ValidationInputError", "accumulated_gramian", "design_matrix", "gramian", "gramian_from_scatter",
    "los_scatter", "skew", "NULL_COMPONENT_TOL", "RANK_RTOL", "atdop", "atdop_from_svd", "observable_degree",
    "observable_degree_from_svd", "rank", "svd",
]
