"""SVD of the attitude-error observability Gramian, ATDOP, observable degree and rank (Wang 2018, eqs 4-15).

Every function is vectorised: a Gramian ``L`` is (..., 3, 3) over the error states [pitch (about body x), roll
(about body y), yaw (about body z)], rad; results are (..., 3) in that order, leading axes passed through.

Units: with ``L = H^T R^-1 H``, H in metres of baseline per radian and R in m^2 of phase noise, ``L`` is in
1/rad^2 per unit measurement variance; ATDOP (eqs 10-12) is then rad per metre of phase noise and the observable
degree (eqs 13-15) has the units of ``L``. Neither depends on the unit convention beyond that scaling.

Tolerances (documented in docs/validation.md):
- :data:`RANK_RTOL`: a singular value counts towards the rank when above ``RANK_RTOL * sigma_max``. A Gramian
  built in float64 from exact geometry has its structural zeros at ~1e-16 sigma_max; geometry the degeneracy
  test (``simkit.validation.degeneracy``) calls non-degenerate keeps its smallest singular value above ~1e-8
  sigma_max, so 1e-12 separates the two by four orders either side.
- :data:`NULL_COMPONENT_TOL`: an ATDOP is infinite when its state has a squared component above this along a
  singular vector whose singular value is below the rank threshold (the angle is not externally observable).
"""
from __future__ import annotations

import numpy as np

from .errors import ValidationInputError
from .jacobi import sym_eig3

RANK_RTOL = 1e-12
NULL_COMPONENT_TOL = 1e-10


def _check_gramian(L, name: str = "L") -> np.ndarray:
    L = np.asarray(L, dtype=float)
    if L.ndim < 2 or L.shape[-2:] != (3, 3):
        raise ValidationInputError(f"{name}: expected a (..., 3, 3) Gramian, got shape {L.shape}")
    return L


def svd(L) -> tuple[np.ndarray, np.ndarray]:
    """Eq. (4) for a symmetric positive semi-definite ``L`` (..., 3, 3): singular values ``sigma`` (..., 3) in
    descending order and the orthogonal ``U`` (..., 3, 3) with ``U[..., i, j]`` the component of state i on
    singular vector j (the layout of the paper's Table 1). Computed by a symmetric eigendecomposition
    (eigenvalues of a PSD matrix are its singular values; round-off negatives are taken in absolute value), by
    Jacobi rotations (:func:`simkit.validation.jacobi.sym_eig3`)."""
    L = _check_gramian(L)
    flat = np.ascontiguousarray(L.reshape(-1, 3, 3))
    lam, vec = sym_eig3(flat)
    return np.abs(lam).reshape(L.shape[:-1]), vec.reshape(L.shape)


def rank_threshold(sigma, rtol: float = RANK_RTOL, atol: float = 0.0) -> np.ndarray:
    """The singular value (..., ) below which a direction counts as unobservable: max(atol, rtol sigma_max)."""
    sigma = np.asarray(sigma, dtype=float)
    return np.maximum(atol, rtol * sigma.max(axis=-1))


def rank_from_svd(sigma, rtol: float = RANK_RTOL, atol: float = 0.0) -> np.ndarray:
    """Number of singular values (..., 3) above :func:`rank_threshold` (an all-zero Gramian has rank 0)."""
    sigma = np.asarray(sigma, dtype=float)
    return (sigma > rank_threshold(sigma, rtol, atol)[..., None]).sum(axis=-1)


def rank(L, rtol: float = RANK_RTOL, atol: float = 0.0) -> np.ndarray:
    """Numerical rank of ``L`` (..., 3, 3): singular values above ``max(atol, rtol sigma_max)``. For a matrix
    known only to a printed precision, pass ``atol`` = the Frobenius norm of the rounding (Weyl's inequality
    bounds each singular value's error by it) and ``rtol=0``."""
    return rank_from_svd(svd(L)[0], rtol, atol)


def atdop_from_svd(sigma, U, rtol: float = RANK_RTOL) -> np.ndarray:
    """PIDOP, RDOP, YDOP (eqs 8, 10-12): sqrt(sum_j U_ij^2 / sigma_j), (..., 3). An angle with a component
    (squared above :data:`NULL_COMPONENT_TOL`) along an unobservable singular vector gets ``inf``."""
    sigma = np.asarray(sigma, dtype=float)
    U2 = np.square(np.asarray(U, dtype=float))
    null = sigma <= rank_threshold(sigma, rtol)[..., None]
    safe = np.where(null, 1.0, sigma)
    d = np.where(null[..., None, :], 0.0, U2 / safe[..., None, :]).sum(axis=-1)
    hidden = np.where(null[..., None, :], U2, 0.0).sum(axis=-1) > NULL_COMPONENT_TOL
    return np.where(hidden, np.inf, np.sqrt(d))


def observable_degree_from_svd(sigma, U) -> np.ndarray:
    """Observable degrees of pitch, roll, yaw errors (eqs 5, 13-15): sqrt(sum_j sigma_j^2 U_ij^2), (..., 3)."""
    sigma = np.asarray(sigma, dtype=float)
    return np.sqrt((np.square(np.asarray(U, dtype=float)) * np.square(sigma)[..., None, :]).sum(axis=-1))


def atdop(L, rtol: float = RANK_RTOL) -> np.ndarray:
    """ATDOP [PIDOP, RDOP, YDOP] (..., 3) of the Gramian ``L`` (..., 3, 3), eqs 10-12 through its SVD;
    ``inf`` for angles that are not externally observable (see :func:`atdop_from_svd`).

    >>> import numpy as np
    >>> atdop(np.diag([4.0, 1.0, 100.0])).round(3).tolist()
    [0.5, 1.0, 0.1]
    """
    return atdop_from_svd(*svd(L), rtol=rtol)


def observable_degree(L) -> np.ndarray:
    """Observable degrees [pitch, roll, yaw] (..., 3) of the Gramian ``L`` (..., 3, 3), eqs 13-15 via its SVD.

    >>> import numpy as np
    >>> observable_degree(np.diag([4.0, 1.0, 100.0])).tolist()
    [4.0, 1.0, 100.0]
    """
    return observable_degree_from_svd(*svd(L))
