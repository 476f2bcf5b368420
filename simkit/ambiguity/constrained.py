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

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .decorrelation import OK, as_problem, new_decorrelated, prepare
from .errors import AmbiguityInputError
from .inner import rotation_fit, sphere_fit
from .search import DEFAULT_MAX_NODES, Best, back_transform, make_search

BOUNDED = 2  # status: search stopped with costs[found:] >= chi2 (a lower bound, see ratio_stop)


class Epoch(NamedTuple):
    """One epoch's float solution (or K stacked along a leading axis), as the kernels take it."""

    a_hat: np.ndarray  # (n,) cycles
    Qa: np.ndarray  # (n, n) cycles^2
    b_hat: np.ndarray  # (p,) m, p = 3 r
    Qb: np.ndarray  # (p, p) m^2
    Qba: np.ndarray  # (p, n) cross-covariance b-a, m cycles


class Constraint(NamedTuple):
    """What a constrained leaf needs: the conditioned float baseline and its weight, plus the constraint."""

    P: np.ndarray  # (p, n) Qba Qa^-1 Z^-T: baseline change per unit of decorrelated ambiguity residual
    v: np.ndarray  # (p,) b_hat, m
    W: np.ndarray  # (p, p) weight of the conditioned baseline Qb(z)^-1, 1/m^2
    U: np.ndarray  # (p, p) eigenvectors of W
    w: np.ndarray  # (p,) eigenvalues of W, ascending
    F: np.ndarray  # (3, r) body-frame baselines, m (attitude only)
    lengths: np.ndarray  # (r,) baseline lengths, m


@njit
def _conditioned(ctx, w, z, budget, dist):
    """``b_hat(z)`` for the leaf ``z`` (p,), or an empty array when the cheap bound already exceeds ``budget``.

    The bound: on the constraint ``|x_j| = l_j``, so ``|c_j - x_j| >= | |c_j| - l_j |`` and the inner minimum is at
    least ``w_min sum_j (|c_j| - l_j)^2``.
    """
    c = ctx.v.copy()
    for k in range(c.shape[0]):
        s = 0.0
        for i in range(z.shape[0]):
            s += ctx.P[k, i] * (w.zhat[i] - z[i])
        c[k] -= s
    lb = 0.0
    for j in range(ctx.lengths.shape[0]):
        nj = math.sqrt(c[3 * j] ** 2 + c[3 * j + 1] ** 2 + c[3 * j + 2] ** 2)
        lb += (nj - ctx.lengths[j]) ** 2
    return c[:0] if dist + ctx.w[0] * lb >= budget else c


@njit
def length_leaf(ctx, dist, w, z, budget, out):
    """C-LAMBDA leaf cost: squared norm plus the exact minimum on the sphere ``|b| = l`` (baseline into ``out``)."""
    c = _conditioned(ctx, w, z, budget, dist)
    if c.shape[0] == 0:
        return math.inf
    return dist + sphere_fit(c, ctx.U, ctx.w, ctx.lengths[0], out)


@njit
def attitude_leaf(ctx, dist, w, z, budget, out):
    """Multivariate constrained leaf cost: squared norm plus the minimum over SO(3) (R row-major into ``out``)."""
    c = _conditioned(ctx, w, z, budget, dist)
    if c.shape[0] == 0:
        return math.inf
    return dist + rotation_fit(c, ctx.W, ctx.F, out)


@njit
def _constraint(ep, w, F, lengths):
    """The :class:`Constraint` of epoch ``ep`` decorrelated into ``w``; ok = False when Qb(z) is not PD."""
    K = np.linalg.solve(ep.Qa, ep.Qba.T).T  # Qba Qa^-1, (p, n)
    Qbz = ep.Qb - K @ ep.Qba.T
    W = np.linalg.inv(0.5 * (Qbz + Qbz.T))
    W = 0.5 * (W + W.T)
    ev, U = np.linalg.eigh(W)
    return ev[0] > 0.0, Constraint(K @ w.Zti.astype(np.float64), ep.b_hat, W, U, ev, F, lengths)


def _batch_solver(leaf_cost):
    """The constrained batch solver for one leaf cost (:func:`length_leaf` or :func:`attitude_leaf`)."""
    search = make_search(leaf_cost)

    @njit(inline="always")  # one call site; see the note above the entry kernels
    def solve_epoch(ep, F, lengths, max_nodes, best, cands, ratio_stop):
        """Decorrelate, then search-and-expand: a first leaf far off the constraint would make search-and-shrink
        start from a huge ellipsoid, so search below chi2 and expand it until m candidates are inside (then
        they are the m best). With ``ratio_stop`` > 0 the expansion also stops once the ellipsoid reaches
        ratio_stop x the best cost: the costs not found are then at least chi2, which is stored in their place
        (status BOUNDED). Writes ``best`` and ``cands`` (m, n) int64; returns (status, i, j, nodes)."""
        w = new_decorrelated(ep.a_hat.shape[0])
        code, i, j = prepare(ep.a_hat, ep.Qa, w)
        if code != OK:
            return code, i, j, 0
        ok, ctx = _constraint(ep, w, F, lengths)
        if not ok:
            return -3, -1, -1, 0
        chi2 = float(ep.a_hat.shape[0] + ep.b_hat.shape[0])
        total = 0
        while True:
            status, nodes, found = search(ctx, w, best, max_nodes - total, chi2)
            total += nodes
            if found == best.costs.shape[0] or status != OK or total >= max_nodes:
                break
            if found >= 1 and ratio_stop > 0.0 and chi2 >= ratio_stop * best.costs[0]:
                best.costs[found:] = chi2
                status = BOUNDED
                break
            chi2 *= 4.0
        cands[:, :] = back_transform(best.cands, w.Zti, w.shift)
        return status, 0, 0, total

    @njit(inline="always")
    def solve_batch(eps, F, lengths, m, max_nodes, k_out, ratio_stop):
        """Every epoch of the stacked ``eps``, ``lengths`` (K, r): (cands, costs, sols, status, nodes, err)."""
        K, n = eps.a_hat.shape
        cands = np.zeros((K, m, n), dtype=np.int64)
        costs = np.full((K, m), np.inf)
        sols = np.full((K, m, k_out), np.nan)
        status = np.zeros(K, dtype=np.int64)
        nodes = np.zeros(K, dtype=np.int64)
        err = np.full(3, -1, dtype=np.int64)
        cz = np.zeros((m, n))
        for k in range(K):
            ep = Epoch(eps.a_hat[k], eps.Qa[k], eps.b_hat[k], eps.Qb[k], eps.Qba[k])
            best = Best(cz, costs[k], sols[k])
            code, i, j, nodes[k] = solve_epoch(ep, F, lengths[k], max_nodes, best, cands[k], ratio_stop)
            status[k] = code
            if code < 0 and err[0] < 0:
                err[0], err[1], err[2] = k, i, j
        return cands, costs, sols, status, nodes, err

    return solve_batch


_solve_length = _batch_solver(length_leaf)
_solve_attitude = _batch_solver(attitude_leaf)


# One cached entry kernel per constraint, so that each compiles (and loads) only its own inner problem.
# solve_batch and solve_epoch are inlined into it (numba IR inlining, one call site each): as separate functions
# each was compiled into its own LLVM module and optimised again inside every caller's linked module, and the
# first attitude_mc solve took 39.5 s of CPU instead of 29.8 s (docs/cold_start.md).
@njit(cache=True)
def _length_batch(eps, F, lengths, m, max_nodes, ratio_stop):
    return _solve_length(eps, F, lengths, m, max_nodes, 3, ratio_stop)


@njit(cache=True)
def _attitude_batch(eps, F, lengths, m, max_nodes, ratio_stop):
    return _solve_attitude(eps, F, lengths, m, max_nodes, 9, ratio_stop)


class ConstrainedResult:
    """Constrained ILS for K epochs: ``candidates`` (K, n_cands, n) int64 best first, ``costs`` (K, n_cands)
    (squared ambiguity norm plus the inner minimum), ``finished`` (K,) bool, ``nodes`` (K,); for one baseline
    ``baselines`` (K, n_cands, 3) m on the sphere |b| = l; for several, ``rotations`` (K, n_cands, 3, 3) body ->
    local frame, and ``baselines`` (K, n_cands, 3, r) = R F. Single-epoch calls drop the leading K axis.
    ``bounded`` (K,) bool: the search stopped early under ``ratio_stop``; then ``costs`` of the candidates not
    found hold a lower bound of their cost (so ``costs[1] / costs[0]`` is a lower bound of the ratio), and their
    ``candidates`` rows are not meaningful. ``finished`` is True for bounded epochs (their best is exact)."""

    def __init__(self, candidates, costs, finished, nodes, baselines, rotations=None, bounded=None):
        self.candidates, self.costs, self.finished, self.nodes = candidates, costs, finished, nodes
        self.baselines, self.rotations = baselines, rotations
        self.bounded = np.zeros_like(finished, dtype=bool) if bounded is None else bounded

    @property
    def status(self):
        return np.where(self.bounded, "bounded", np.where(self.finished, "finished", "not finished"))


def _stack(x, ndim, what, K=None):
    arr = np.ascontiguousarray(x, dtype=np.float64)
    if arr.ndim == ndim - 1:
        arr = arr[None]
    if arr.ndim != ndim or (K is not None and arr.shape[0] != K):
        raise AmbiguityInputError(what, f"shape {np.shape(x)}; expected {ndim - 1} dims per epoch, "
                                        f"optionally stacked over K epochs{'' if K is None else f' (K = {K})'}")
    return arr


def _epochs(a_hat, Qa, b_hat, Qb, Qba) -> Epoch:
    """The inputs stacked over K epochs (a single epoch gets K = 1), shapes checked."""
    A = _stack(a_hat, 2, "a_hat")
    K, n = A.shape
    ep = Epoch(A, _stack(Qa, 3, "Qa", K), _stack(b_hat, 2, "b_hat", K), _stack(Qb, 3, "Qb", K),
               _stack(Qba, 3, "Qba", K))
    p = ep.b_hat.shape[1]
    for what, want in (("Qa", (n, n)), ("Qb", (p, p)), ("Qba", (p, n))):
        if getattr(ep, what).shape[1:] != want:
            raise AmbiguityInputError(what, f"shape {getattr(ep, what).shape[1:]} per epoch; expected {want}")
    for k in range(K):
        as_problem(A[k], ep.Qa[k], what=f"[{k}]" if np.ndim(a_hat) > 1 else "")
    return ep


def _run(kernel, ep, single, F, lengths, n_cands, max_nodes, ratio_stop=0.0):
    """Run ``kernel`` (:func:`_length_batch` or :func:`_attitude_batch`) and wrap its output; ``lengths`` (K, r)."""
    if int(n_cands) != n_cands or n_cands < 1:
        raise AmbiguityInputError("n_cands", f"{n_cands!r}; expected an integer >= 1")
    cands, costs, sols, status, nodes, err = kernel(ep, F, lengths, int(n_cands), int(max_nodes), float(ratio_stop))
    if err[0] >= 0:
        if err[1] < 0:
            raise AmbiguityInputError(f"Qb[{err[0]}]", "conditional baseline covariance is not positive definite")
        raise AmbiguityInputError(f"Qa[{int(err[0])}]", "not symmetric positive definite (or a_hat not finite)")
    finished, bounded = (status == OK) | (status == BOUNDED), status == BOUNDED
    if kernel is _length_batch:
        res = ConstrainedResult(cands, costs, finished, nodes, sols, None, bounded)
    else:
        R = sols.reshape(len(cands), -1, 3, 3)
        res = ConstrainedResult(cands, costs, finished, nodes, R @ F, R, bounded)
    if single:
        res = ConstrainedResult(res.candidates[0], res.costs[0], bool(res.finished[0]), int(res.nodes[0]),
                                res.baselines[0], None if res.rotations is None else res.rotations[0],
                                bool(res.bounded[0]))
    return res


def baseline_constrained_ils(a_hat, Qa, b_hat, Qb, Qba, length, n_cands=2, max_nodes=DEFAULT_MAX_NODES,
                             ratio_stop=0.0):
    """C-LAMBDA: ambiguities and baseline for one baseline of known ``length`` (m).

    ``ratio_stop`` > 0: stop looking for the 2nd..n_cands-th candidates once the cost bound reaches ratio_stop x
    the best cost (``bounded``; their costs are then lower bounds), which is all a ratio test at that threshold
    needs and avoids enumerating a huge ellipsoid when the best candidate is far better than any other.

    Shapes per epoch: ``a_hat`` (n,) cycles, ``Qa`` (n, n), ``b_hat`` (3,) m, ``Qb`` (3, 3), ``Qba`` (3, n); stack
    them over a leading K axis for a batch (``length`` scalar or (K,)). Returns :class:`ConstrainedResult`.
    """
    lengths = np.atleast_1d(np.asarray(length, dtype=np.float64))
    if np.shape(b_hat)[-1] != 3:
        raise AmbiguityInputError("b_hat", f"shape {np.shape(b_hat)}; expected (3,) per epoch")
    if not np.all(lengths > 0):
        raise AmbiguityInputError("length", f"{length!r}; expected a positive baseline length in metres")
    ep = _epochs(a_hat, Qa, b_hat, Qb, Qba)
    K = ep.a_hat.shape[0]
    if lengths.shape not in ((1,), (K,)):
        raise AmbiguityInputError("length", f"shape {lengths.shape}; expected a scalar or ({K},), one per epoch")
    lengths = np.ascontiguousarray(np.broadcast_to(lengths[:, None], (K, 1)))
    return _run(_length_batch, ep, np.ndim(a_hat) == 1, np.zeros((3, 1)), lengths, n_cands, max_nodes, ratio_stop)


def attitude_constrained_ils(a_hat, Qa, b_hat, Qb, Qba, body_baselines, n_cands=2, max_nodes=DEFAULT_MAX_NODES,
                             ratio_stop=0.0):
    """Multivariate constrained LAMBDA: ambiguities and attitude R (body -> local) for r baselines.

    ``body_baselines`` (3, r): the baselines in the body frame (m). Per epoch: ``a_hat`` (r n,) stacked by
    baseline, ``Qa`` (r n, r n), ``b_hat`` (3 r,), ``Qb`` (3 r, 3 r), ``Qba`` (3 r, r n); stack over K for a batch.
    The inner minimum over SO(3) starts from the orthogonal Procrustes solution and is refined by Gauss-Newton.
    ``ratio_stop``: as in :func:`baseline_constrained_ils`.
    """
    F = np.ascontiguousarray(body_baselines, dtype=np.float64)
    if F.ndim != 2 or F.shape[0] != 3 or np.shape(b_hat)[-1] != 3 * F.shape[1]:
        raise AmbiguityInputError("body_baselines", f"shape {F.shape}; expected (3, r) with b_hat of 3 r values")
    ep = _epochs(a_hat, Qa, b_hat, Qb, Qba)
    lengths = np.ascontiguousarray(np.broadcast_to(np.linalg.norm(F, axis=0), (ep.a_hat.shape[0], F.shape[1])))
    return _run(_attitude_batch, ep, np.ndim(a_hat) == 1, F, lengths, n_cands, max_nodes, ratio_stop)
