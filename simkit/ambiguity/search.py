"""Integer least squares by search-and-shrink (de Jonge & Tiberius 1996; Chang, Yang & Zhou 2005).

The search runs depth-first over the decorrelated ambiguities from index ``n-1`` down to 0, visiting the integers
of each level in order of distance from the conditional estimate (Schnorr-Euchner zig-zag), and shrinks the
ellipsoid to the largest of the ``m`` best costs found once ``m`` candidates are held. It is exact: when it
finishes, the candidates are the ``m`` integer vectors with the smallest cost.

The cost of a leaf is computed by a ``leaf_cost`` function: :func:`ils_leaf` (the squared norm
``(a_hat - a)^T Q^-1 (a_hat - a)``) here, the baseline-constrained costs in :mod:`.constrained`;
:func:`make_search` builds the search for one of them. Pruning on
the partial squared norm stays exact as long as the leaf cost is never below the squared norm.

Compile time (why the kernels are shaped this way): numba compiles a kernel together with everything it calls.
With the leaf cost chosen by a run-time ``mode``, a plain ``ils`` compiled the SO(3) and sphere fits (LAPACK SVD,
solve, eigh) as well: about 14 s of a cold first call here. One search per leaf cost, built by
:func:`make_search` with the leaf as a compile-time constant, lets ``ils`` compile only the squared norm, and the
constrained kernels compile only when a constrained solver is called. (Passing the leaf function as a run-time
argument instead would put a pointer to the Python dispatcher object into the machine code, which numba then
refuses to cache.) The searches themselves are not cached: the entry kernels that embed them are.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .decorrelation import NOT_FINISHED, OK, as_problem, new_decorrelated, prepare, raise_for_status
from .errors import AmbiguityInputError
from .warmup import jit_when_ready

DEFAULT_MAX_NODES = 10_000_000
_F64 = np.dtype(np.float64)  # numpy's native float64 dtype is one shared object


class Best(NamedTuple):
    """The ``m`` best leaves found by :func:`search_into` (numba-compatible named tuple), best first at the end."""

    cands: np.ndarray  # (m, n) float, integer-valued decorrelated ambiguities
    costs: np.ndarray  # (m,) leaf costs (inf where fewer were found)
    sols: np.ndarray  # (m, k) the leaf function's inner solution per candidate (k = 0 for plain ILS)


@njit(inline="always")
def ils_leaf(ctx, dist, w, z, budget, out):
    """Leaf cost of plain ILS: the squared norm itself (``ctx`` unused)."""
    return dist


@njit(inline="always")
def _enter(L, zhat, acc, dist, zc, z, step, k, newdist):
    """Descend to level ``k`` below a node of partial squared norm ``newdist``; returns the new residual.

    ``acc[k, j] = sum_{i >= k} L[i, j] (z_i - zc_i)`` for j < k; ``dist[k]`` is the squared norm of levels
    k+1 .. n-1, ``zc[k]`` the conditional estimate of level k, ``z[k]`` the integer tried there and ``step[k]``
    its next zig-zag step.
    """
    e = z[k + 1] - zc[k + 1]
    for j in range(k + 1):
        acc[k + 1, j] = acc[k + 2, j] + L[k + 1, j] * e
    dist[k] = newdist
    zc[k] = zhat[k] + acc[k + 1, k]
    return _start_level(zc, z, step, k)


@njit(inline="always")
def _start_level(zc, z, step, k):
    """Start level ``k`` at the integer nearest its conditional estimate; returns the residual zc - z."""
    z[k] = math.floor(zc[k] + 0.5)
    y = zc[k] - z[k]
    step[k] = 1.0 if y >= 0.0 else -1.0
    return y


@njit(inline="always")
def _zigzag(zc, z, step, k):
    """Move level ``k`` to its next integer (alternating around the estimate); returns the new residual."""
    z[k] += step[k]
    step[k] = -step[k] - (1.0 if step[k] > 0.0 else -1.0)
    return zc[k] - z[k]


@njit
def _worst(costs):
    """Index of the largest held cost (the first one on ties)."""
    slot = 0
    for i in range(1, costs.shape[0]):
        if costs[i] > costs[slot]:
            slot = i
    return slot


@njit
def _keep(best, found, z, out, cost, chi2):
    """Store a leaf among the best, in place of the worst once all ``m`` are held; returns (found, new bound).

    The bound stays ``chi2`` until ``m`` leaves are held, then it is the largest held cost (the shrink).
    Explicit loops rather than slice assignment and ``max()``: same speed, a fraction of the compile time.
    """
    m = best.costs.shape[0]
    slot = found if found < m else _worst(best.costs)
    for i in range(z.shape[0]):
        best.cands[slot, i] = z[i]
    for i in range(out.shape[0]):
        best.sols[slot, i] = out[i]
    best.costs[slot] = cost
    found = min(found + 1, m)
    return found, (chi2 if found < m else best.costs[_worst(best.costs)])


@njit
def _sort_best(best):
    """Sort the held leaves by cost (insertion sort; m is small)."""
    for i in range(1, best.costs.shape[0]):
        j = i
        while j > 0 and best.costs[j] < best.costs[j - 1]:
            best.costs[j], best.costs[j - 1] = best.costs[j - 1], best.costs[j]
            for q in range(best.cands.shape[1]):
                best.cands[j, q], best.cands[j - 1, q] = best.cands[j - 1, q], best.cands[j, q]
            for q in range(best.sols.shape[1]):
                best.sols[j, q], best.sols[j - 1, q] = best.sols[j - 1, q], best.sols[j, q]
            j -= 1


def make_search(leaf_cost):
    """:func:`search_into` specialised for one leaf-cost function (numba compiles it in as a direct call)."""

    @njit
    def search_into(ctx, w, best, max_nodes, chi2_start=math.inf):
        """Search-and-shrink for the ``m`` best integer vectors of the decorrelated problem ``w``.

        ``leaf_cost(ctx, dist, w, z, budget, out)`` gives a leaf's cost from its squared norm ``dist`` (it may
        return inf when the cost cannot beat ``budget``) and writes its inner solution into ``out``. Only costs
        below ``chi2_start`` are searched for (search-and-expand reruns with a larger one when fewer than m were
        found). Fills ``best`` (:class:`Best`), sorted by cost. Returns (status, nodes, n_found).
        """
        L, zhat, d = w.L, w.zhat, w.d  # locals: the hot loop then sees plain arrays, not tuple members
        n = d.shape[0]
        acc, dist = np.zeros((n + 1, n)), np.zeros(n)
        zc, z, step = np.empty(n), np.empty(n), np.empty(n)
        out = np.empty(best.sols.shape[1])
        for i in range(best.costs.shape[0]):
            best.costs[i] = math.inf
        found, chi2, nodes, status = 0, chi2_start, 0, OK
        k = n - 1
        zc[k] = zhat[k]
        y = _start_level(zc, z, step, k)
        while True:
            nodes += 1
            if nodes > max_nodes:
                status = NOT_FINISHED
                break
            newdist = dist[k] + y * y / d[k]
            if newdist < chi2:
                if k > 0:
                    k -= 1
                    y = _enter(L, zhat, acc, dist, zc, z, step, k, newdist)
                    continue
                cost = leaf_cost(ctx, newdist, w, z, chi2, out)
                if cost < chi2:
                    found, chi2 = _keep(best, found, z, out, cost, chi2)
                y = _zigzag(zc, z, step, 0)
            else:
                if k == n - 1:
                    break
                k += 1
                y = _zigzag(zc, z, step, k)
        _sort_best(best)
        return status, nodes, found

    return search_into


ils_search = make_search(ils_leaf)


@njit(cache=True)
def back_transform(cz, Zti, shift):
    """Candidates in the decorrelated space (m, n) float -> original integers (m, n) int64: a = Zti z + shift."""
    m, n = cz.shape
    out = np.empty((m, n), dtype=np.int64)
    for q in range(m):
        for r in range(n):
            s = shift[r]
            for c in range(n):
                s += Zti[r, c] * np.int64(cz[q, c])
            out[q, r] = s
    return out


@njit(cache=True)
def _ils_kernel(a, Q, m, max_nodes):
    n = a.shape[0]
    w = new_decorrelated(n)
    best = Best(np.zeros((m, n)), np.full(m, math.inf), np.empty((m, 0)))
    code, i, j = prepare(a, Q, w)
    nodes = 0
    if code == OK:
        code, nodes, _ = ils_search(None, w, best, max_nodes)
    # the work arrays go back packed into one float and one integer array: boxing each array into a Python
    # object costs about 0.3 us, a third of an n = 10 solve; ILSResult unpacks them only when asked
    floats = np.empty(n * n + 2 * n)
    ints = np.empty(2 * n * n + n, dtype=np.int64)
    for r in range(n):
        for c in range(n):
            floats[r * n + c] = w.L[r, c]
            ints[r * n + c] = w.Z[r, c]
            ints[n * n + r * n + c] = w.Zti[r, c]
        floats[n * n + r] = w.d[r]
        floats[n * n + n + r] = w.zhat[r]
        ints[2 * n * n + r] = w.shift[r]
    return code, i, j, back_transform(best.cands, w.Zti, w.shift), best.costs, nodes, floats, ints


@njit(cache=True)
def _ils_batch_kernel(A, Qs, m, max_nodes):
    K, n = A.shape
    cands = np.zeros((K, m, n), dtype=np.int64)
    costs = np.full((K, m), math.inf)
    status = np.zeros(K, dtype=np.int64)
    nodes = np.zeros(K, dtype=np.int64)
    dd = np.empty((K, n))
    err = np.full(3, -1, dtype=np.int64)  # first bad epoch, i, j
    w = new_decorrelated(n)
    cz, sols = np.zeros((m, n)), np.empty((m, 0))
    for k in range(K):
        best = Best(cz, costs[k], sols)
        code, i, j = prepare(A[k], Qs[k if Qs.shape[0] > 1 else 0], w)
        dd[k] = w.d
        status[k] = code
        if code != OK:
            if err[0] < 0:
                err[0], err[1], err[2] = k, i, j
            continue
        status[k], nodes[k], _ = ils_search(None, w, best, max_nodes)
        cands[k] = back_transform(best.cands, w.Zti, w.shift)
    return cands, costs, status, nodes, dd, err


# Interpreted up to n = 40 while the kernel compiles: 0.1 ms (n = 3) to ~0.1 s (n = 40, badly conditioned) per
# solve here, against 4-6 s of compilation (see .warmup).
_ILS = jit_when_ready(_ils_kernel, lambda a, *_: a.shape[0], max_interpreted_n=40)


def _unpack(buf, n, squares, k):
    """Part ``k`` of a buffer packed by ``_ils_kernel``: ``squares`` (n, n) matrices first, then (n,) vectors."""
    if k < squares:
        return buf[k * n * n:(k + 1) * n * n].reshape(n, n)
    start = squares * n * n + (k - squares) * n
    return buf[start:start + n]


class ILSResult:
    """Integer least-squares solution of one problem.

    Attributes: ``candidates`` (n_cands, n) int64, best first; ``sqnorms`` (n_cands,) squared norms
    ``(a_hat - a)^T Q^-1 (a_hat - a)`` (inf where fewer candidates were found); ``status`` ("finished" or
    "not finished": the work cap was reached and the candidates are only the best found so far); ``nodes`` (search
    nodes visited); the decorrelation ``Z``, ``Zti`` (= Z^-T), ``L``, ``d`` (conditional variances of z, cycles^2),
    ``z_hat`` (Z^T (a_hat - shift)) and the integer ``shift`` (round(a_hat)) taken out before the search.
    """

    __slots__ = ("candidates", "sqnorms", "finished", "nodes", "_floats", "_ints")

    def __init__(self, candidates, sqnorms, finished, nodes, floats, ints):
        """``floats`` packs L (n*n), d and z_hat; ``ints`` packs Z (n*n), Zti (n*n) and shift (see _ils_kernel)."""
        self.candidates, self.sqnorms, self.finished, self.nodes = candidates, sqnorms, finished, nodes
        self._floats, self._ints = floats, ints

    L = property(lambda self: _unpack(self._floats, self.candidates.shape[1], 1, 0))
    d = property(lambda self: _unpack(self._floats, self.candidates.shape[1], 1, 1))
    z_hat = property(lambda self: _unpack(self._floats, self.candidates.shape[1], 1, 2))
    Z = property(lambda self: _unpack(self._ints, self.candidates.shape[1], 2, 0))
    Zti = property(lambda self: _unpack(self._ints, self.candidates.shape[1], 2, 1))
    shift = property(lambda self: _unpack(self._ints, self.candidates.shape[1], 2, 2))

    @property
    def status(self) -> str:
        return "finished" if self.finished else "not finished"

    @property
    def best(self):
        return self.candidates[0]

    @property
    def ratio(self) -> float:
        """sqnorm(2nd) / sqnorm(best), the ratio-test statistic (>= 1).

        NaN when solved with ``n_cands=1``: the statistic needs a second candidate that was never searched for,
        and NaN fails every ``ratio >= threshold`` comparison, so no fix is accepted on it. (inf when a second
        candidate was asked for but none exists within the work cap, or when the best norm is 0.)
        """
        if self.sqnorms.shape[0] < 2:
            return math.nan
        s0, s1 = float(self.sqnorms[0]), float(self.sqnorms[1])
        return math.inf if s0 == 0.0 else s1 / s0

    @property
    def Qz(self):
        """Decorrelated covariance Z^T Q Z = L^T diag(d) L (cycles^2)."""
        return self.L.T @ (self.d[:, None] * self.L)

    def __repr__(self):
        return f"ILSResult(best={self.candidates[0].tolist()}, sqnorms={self.sqnorms.tolist()}, {self.status})"


def _check_counts(n_cands, max_nodes):
    if int(n_cands) != n_cands or n_cands < 1:
        raise AmbiguityInputError("n_cands", f"{n_cands!r}; expected an integer >= 1")
    if int(max_nodes) != max_nodes or max_nodes < 1:
        raise AmbiguityInputError("max_nodes", f"{max_nodes!r}; expected an integer >= 1")


def ils(a_hat, Q, n_cands=2, max_nodes=DEFAULT_MAX_NODES) -> ILSResult:
    """The ``n_cands`` best integer vectors for float ambiguities ``a_hat`` (n,) with covariance ``Q`` (n, n).

    Units: cycles and cycles^2. ``max_nodes`` caps the search work; when reached, ``status`` is "not finished".
    Raises :class:`AmbiguityInputError` for a wrong shape, non-finite values, a non-symmetric or a
    non-positive-definite ``Q``.
    """
    if type(n_cands) is not int or type(max_nodes) is not int or n_cands < 1 or max_nodes < 1:
        _check_counts(n_cands, max_nodes)
        n_cands, max_nodes = int(n_cands), int(max_nodes)
    a, Qm = a_hat, Q
    # the common case (C-contiguous float64 arrays of matching shapes) is recognised with the cheapest checks:
    # at n = 10 the whole solve takes ~7 us, and numpy's dtype comparisons and flags objects cost ~0.1 us each
    if not (type(a) is np.ndarray and type(Qm) is np.ndarray and a.dtype is _F64 and Qm.dtype is _F64
            and a.ndim == 1 and a.size and Qm.shape == (a.size, a.size) and a.flags.c_contiguous
            and Qm.flags.c_contiguous):
        a, Qm = as_problem(a_hat, Q)  # converts, or raises naming the wrong shape
    code, i, j, cands, costs, nodes, floats, ints = _ILS.call(a, Qm, n_cands, max_nodes)
    if code < 0:
        raise_for_status(code, i, j)
    return ILSResult(cands, costs, code == OK, nodes, floats, ints)


class ILSBatchResult:
    """Solutions of K problems of one size: ``candidates`` (K, n_cands, n) int64, ``sqnorms`` (K, n_cands),
    ``finished`` (K,) bool, ``nodes`` (K,), ``d`` (K, n) conditional variances after decorrelation (cycles^2)."""

    __slots__ = ("candidates", "sqnorms", "finished", "nodes", "d")

    def __init__(self, candidates, sqnorms, finished, nodes, d):
        self.candidates, self.sqnorms, self.finished, self.nodes, self.d = candidates, sqnorms, finished, nodes, d

    @property
    def status(self):
        return np.where(self.finished, "finished", "not finished")


def ils_batch(a_hat, Q, n_cands=2, max_nodes=DEFAULT_MAX_NODES):
    """ILS for many epochs in one call.

    ``a_hat`` (K, n) and ``Q`` (K, n, n), or one ``Q`` (n, n) shared by every epoch: returns an
    :class:`ILSBatchResult`. A list of (n_k,) vectors and a list
    of (n_k, n_k) matrices (n varying): returns a list of :class:`ILSBatchResult` rows, one per epoch, as
    ``(candidates (n_cands, n_k), sqnorms, finished)`` tuples, solved grouped by size.
    """
    _check_counts(n_cands, max_nodes)
    if isinstance(a_hat, (list, tuple)):
        return _ils_list(a_hat, Q, int(n_cands), int(max_nodes))
    A = np.ascontiguousarray(a_hat, dtype=np.float64)
    Qs = np.ascontiguousarray(Q, dtype=np.float64)
    if A.ndim != 2 or A.shape[1] == 0:
        raise AmbiguityInputError("a_hat", f"shape {A.shape}; expected (K, n) for a batch")
    if Qs.ndim == 2:
        Qs = Qs[None]
    if Qs.shape[1:] != (A.shape[1], A.shape[1]) or Qs.shape[0] not in (1, A.shape[0]):
        raise AmbiguityInputError("Q", f"shape {Qs.shape}; expected {(A.shape[0], A.shape[1], A.shape[1])}")
    cands, costs, status, nodes, d, err = _ils_batch_kernel(A, Qs, int(n_cands), int(max_nodes))
    if err[0] >= 0:
        raise_for_status(int(status[err[0]]), int(err[1]), int(err[2]), what=f"[{int(err[0])}]")
    return ILSBatchResult(cands, costs, status == OK, nodes, d)


def _ils_list(a_list, Q_list, n_cands, max_nodes):
    if len(a_list) != len(Q_list):
        raise AmbiguityInputError("Q", f"{len(Q_list)} matrices for {len(a_list)} float vectors")
    probs = [as_problem(a, Q, what=f"[{k}]") for k, (a, Q) in enumerate(zip(a_list, Q_list))]
    sizes = np.array([a.size for a, _ in probs])
    out = [None] * len(probs)
    for n in np.unique(sizes):
        idx = np.flatnonzero(sizes == n)
        A = np.stack([probs[k][0] for k in idx])
        Qs = np.stack([probs[k][1] for k in idx])
        cands, costs, status, _, _, err = _ils_batch_kernel(A, Qs, n_cands, max_nodes)
        if err[0] >= 0:
            raise_for_status(int(status[err[0]]), int(err[1]), int(err[2]), what=f"[{int(idx[err[0]])}]")
        for r, k in enumerate(idx):
            out[k] = (cands[r], costs[r], bool(status[r] == OK))
    return out
