"""Baseline-constrained integer least squares for GNSS attitude.

Model (single epoch, double differences from a master antenna): ``E[y] = A a + B b`` with float solution
``a_hat`` (cycles), ``b_hat`` (m), covariances ``Qa``, ``Qb``, ``Qba`` (cross-covariance b-a). The constrained ILS
(Teunissen 2010; Giorgi et al. 2010, 2012) minimises over integers z

    ||a_hat - z||^2_Qa + min_{b in C} ||b_hat(z) - b||^2_Qb(z),
    b_hat(z) = b_hat - Qba Qa^-1 (a_hat - z),  Qb(z) = Qb - Qba Qa^-1 Qab,

with C = {|b| = l} for one baseline of known length (C-LAMBDA) and C = {vec(R F) : R in SO(3)} for r baselines of
known body-frame geometry F (3, r) (multivariate constrained LAMBDA). The search is the search-and-shrink of
:mod:`.search` in the decorrelated space of Qa with the constrained cost at the leaves (the first term bounds it
from below, so pruning on it is exact). The inner problems are in :mod:`.inner`.
Ordering for r baselines: ``a_hat = [a_1; ...; a_r]`` (baseline-major), ``b_hat = [b_1; ...; b_r]``.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .decorrelation import OK, as_problem
from .errors import AmbiguityInputError
from .search import DEFAULT_MAX_NODES, MODE_ATTITUDE, MODE_LENGTH, back_transform, prepare_new, search_into


@njit(cache=True)
def _solve_one(a, Qa, bhat, Qb, Qba, mode, F, lengths, m, max_nodes, cands, costs, sols):
    n = a.shape[0]
    code, i, j, shift, L, d, Z, Zti, zhat = prepare_new(a, Qa)
    if code != OK:
        return code, i, j, 0
    K = np.linalg.solve(Qa, Qba.T).T  # Qba Qa^-1, (p, n)
    P = K @ Zti.astype(np.float64)
    Qbz = Qb - K @ Qba.T
    W = np.linalg.inv(0.5 * (Qbz + Qbz.T))
    W = 0.5 * (W + W.T)
    w, U = np.linalg.eigh(W)
    if not w[0] > 0.0:
        return -3, -1, -1, 0
    cz = np.zeros((m, n))
    # search-and-expand: a first leaf far off the constraint would make search-and-shrink start from a huge
    # ellipsoid, so search below chi2 and expand it until m candidates are inside (then they are the m best)
    chi2 = float(n + bhat.shape[0])
    total = 0
    while True:
        status, nodes, found = search_into(zhat, L, d, max_nodes - total, mode, P, bhat, W, U, w, F, lengths, cz,
                                           costs, sols, chi2)
        total += nodes
        if found == m or status != OK or total >= max_nodes:
            break
        chi2 *= 4.0
    cands[:, :] = back_transform(cz, Zti, shift)
    return status, 0, 0, total


@njit(cache=True)
def _solve_batch(A, Qa, Bh, Qb, Qba, mode, F, lengths, m, max_nodes):
    K, n = A.shape
    k_out = 3 if mode == MODE_LENGTH else 9
    cands = np.zeros((K, m, n), dtype=np.int64)
    costs = np.full((K, m), np.inf)
    sols = np.full((K, m, k_out), np.nan)
    status = np.zeros(K, dtype=np.int64)
    nodes = np.zeros(K, dtype=np.int64)
    err = np.full(3, -1, dtype=np.int64)
    for k in range(K):
        if mode == MODE_LENGTH:
            ln = lengths[k:k + 1] if lengths.shape[0] == K else lengths[0:1]
        else:
            ln = lengths
        code, i, j, nodes[k] = _solve_one(A[k], Qa[k], Bh[k], Qb[k], Qba[k], mode, F, ln, m, max_nodes,
                                          cands[k], costs[k], sols[k])
        status[k] = code
        if code < 0 and err[0] < 0:
            err[0], err[1], err[2] = k, i, j
    return cands, costs, sols, status, nodes, err


class ConstrainedResult:
    """Constrained ILS for K epochs: ``candidates`` (K, n_cands, n) int64 best first, ``costs`` (K, n_cands)
    (squared ambiguity norm plus the inner minimum), ``finished`` (K,) bool, ``nodes`` (K,); for one baseline
    ``baselines`` (K, n_cands, 3) m on the sphere |b| = l; for several, ``rotations`` (K, n_cands, 3, 3) body ->
    local frame, and ``baselines`` (K, n_cands, 3, r) = R F. Single-epoch calls drop the leading K axis."""

    def __init__(self, candidates, costs, finished, nodes, baselines, rotations=None):
        self.candidates, self.costs, self.finished, self.nodes = candidates, costs, finished, nodes
        self.baselines, self.rotations = baselines, rotations

    @property
    def status(self):
        return np.where(self.finished, "finished", "not finished")


def _stack(x, ndim, what, K=None):
    arr = np.ascontiguousarray(x, dtype=np.float64)
    if arr.ndim == ndim - 1:
        arr = arr[None]
    if arr.ndim != ndim or (K is not None and arr.shape[0] != K):
        raise AmbiguityInputError(what, f"shape {np.shape(x)}; expected {ndim - 1} dims per epoch, "
                                        f"optionally stacked over K epochs{'' if K is None else f' (K = {K})'}")
    return arr


def _run(a_hat, Qa, b_hat, Qb, Qba, mode, F, lengths, n_cands, max_nodes):
    A = _stack(a_hat, 2, "a_hat")
    single = np.ndim(a_hat) == 1
    K, n = A.shape
    Qa_ = _stack(Qa, 3, "Qa", K)
    Bh = _stack(b_hat, 2, "b_hat", K)
    p = Bh.shape[1]
    Qb_ = _stack(Qb, 3, "Qb", K)
    Qba_ = _stack(Qba, 3, "Qba", K)
    if Qa_.shape[1:] != (n, n):
        raise AmbiguityInputError("Qa", f"shape {Qa_.shape[1:]} per epoch; expected ({n}, {n})")
    if Qb_.shape[1:] != (p, p):
        raise AmbiguityInputError("Qb", f"shape {Qb_.shape[1:]} per epoch; expected ({p}, {p})")
    if Qba_.shape[1:] != (p, n):
        raise AmbiguityInputError("Qba", f"shape {Qba_.shape[1:]} per epoch; expected ({p}, {n})")
    for k in range(K):
        as_problem(A[k], Qa_[k], what=f"[{k}]" if not single else "")
    if int(n_cands) < 1:
        raise AmbiguityInputError("n_cands", f"{n_cands!r}; expected an integer >= 1")
    cands, costs, sols, status, nodes, err = _solve_batch(A, Qa_, Bh, Qb_, Qba_, mode, F, lengths, int(n_cands),
                                                          int(max_nodes))
    if err[0] >= 0:
        if err[1] < 0:
            raise AmbiguityInputError(f"Qb[{err[0]}]", "conditional baseline covariance is not positive definite")
        raise AmbiguityInputError(f"Qa[{int(err[0])}]", "not symmetric positive definite (or a_hat not finite)")
    finished = status == OK
    if mode == MODE_LENGTH:
        res = ConstrainedResult(cands, costs, finished, nodes, sols)
    else:
        R = sols.reshape(K, -1, 3, 3)
        res = ConstrainedResult(cands, costs, finished, nodes, R @ F, R)
    if single:
        res = ConstrainedResult(res.candidates[0], res.costs[0], bool(res.finished[0]), int(res.nodes[0]),
                                res.baselines[0], None if res.rotations is None else res.rotations[0])
    return res


def baseline_constrained_ils(a_hat, Qa, b_hat, Qb, Qba, length, n_cands=2, max_nodes=DEFAULT_MAX_NODES):
    """C-LAMBDA: ambiguities and baseline for one baseline of known ``length`` (m).

    Shapes per epoch: ``a_hat`` (n,) cycles, ``Qa`` (n, n), ``b_hat`` (3,) m, ``Qb`` (3, 3), ``Qba`` (3, n); stack
    them over a leading K axis for a batch (``length`` scalar or (K,)). Returns :class:`ConstrainedResult`.
    """
    lengths = np.atleast_1d(np.asarray(length, dtype=np.float64))
    if np.shape(b_hat)[-1] != 3:
        raise AmbiguityInputError("b_hat", f"shape {np.shape(b_hat)}; expected (3,) per epoch")
    if not np.all(lengths > 0):
        raise AmbiguityInputError("length", f"{length!r}; expected a positive baseline length in metres")
    return _run(a_hat, Qa, b_hat, Qb, Qba, MODE_LENGTH, np.zeros((3, 1)), lengths, n_cands, max_nodes)


def attitude_constrained_ils(a_hat, Qa, b_hat, Qb, Qba, body_baselines, n_cands=2, max_nodes=DEFAULT_MAX_NODES):
    """Multivariate constrained LAMBDA: ambiguities and attitude R (body -> local) for r baselines.

    ``body_baselines`` (3, r): the baselines in the body frame (m). Per epoch: ``a_hat`` (r n,) stacked by
    baseline, ``Qa`` (r n, r n), ``b_hat`` (3 r,), ``Qb`` (3 r, 3 r), ``Qba`` (3 r, r n); stack over K for a batch.
    The inner minimum over SO(3) starts from the orthogonal Procrustes solution and is refined by Gauss-Newton.
    """
    F = np.ascontiguousarray(body_baselines, dtype=np.float64)
    if F.ndim != 2 or F.shape[0] != 3 or np.shape(b_hat)[-1] != 3 * F.shape[1]:
        raise AmbiguityInputError("body_baselines", f"shape {F.shape}; expected (3, r) with b_hat of 3 r values")
    return _run(a_hat, Qa, b_hat, Qb, Qba, MODE_ATTITUDE, F, np.linalg.norm(F, axis=0), n_cands, max_nodes)
