"""Integer least squares by search-and-shrink (de Jonge & Tiberius 1996; Chang, Yang & Zhou 2005).

The search runs depth-first over the decorrelated ambiguities from index ``n-1`` down to 0, visiting the integers
of each level in order of distance from the conditional estimate (Schnorr-Euchner zig-zag), and shrinks the
ellipsoid to the largest of the ``m`` best squared norms found once ``m`` candidates are held. It is exact:
when it finishes, the candidates are the ``m`` integer vectors with the smallest ``(a_hat - a)^T Q^-1 (a_hat - a)``.

The same kernel serves the baseline-constrained problems (``mode`` 1: one baseline of known length, ``mode`` 2:
several baselines of known body-frame geometry): a leaf's cost is its squared norm plus the inner problem's
minimum, and pruning on the partial squared norm stays valid because the inner minimum is non-negative.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .decorrelation import (ERR_NONFINITE, ERR_NOT_PD, NOT_FINISHED, OK, as_problem, check_matrix, ltdl_into,
                            raise_for_status, reduce_into)
from .errors import AmbiguityInputError
from .inner import rotation_fit, sphere_fit

DEFAULT_MAX_NODES = 10_000_000
MODE_ILS, MODE_LENGTH, MODE_ATTITUDE = 0, 1, 2


@njit(cache=True)
def _leaf_cost(mode, dist, zhat, z, P, v, W, U, w, F, lengths, budget, out):
    if mode == MODE_ILS:
        return dist
    p = v.shape[0]
    n = zhat.shape[0]
    c = v.copy()
    for k in range(p):
        s = 0.0
        for i in range(n):
            s += P[k, i] * (zhat[i] - z[i])
        c[k] -= s
    # cheap lower bound of the inner minimum: |x_j| = l_j on the constraint, so |c_j - x_j| >= | |c_j| - l_j |
    lb = 0.0
    for j in range(lengths.shape[0]):
        nj = math.sqrt(c[3 * j] ** 2 + c[3 * j + 1] ** 2 + c[3 * j + 2] ** 2)
        lb += (nj - lengths[j]) ** 2
    if dist + w[0] * lb >= budget:
        return math.inf
    if mode == MODE_LENGTH:
        return dist + sphere_fit(c, U, w, lengths[0], out)
    return dist + rotation_fit(c, W, F, out)


@njit(cache=True)
def search_into(zhat, L, d, max_nodes, mode, P, v, W, U, w, F, lengths, cands, costs, sols, chi2_start=math.inf):
    """Search-and-shrink for the ``m = cands.shape[0]`` best integer vectors of the decorrelated problem.

    Only costs below ``chi2_start`` are searched for (the search-and-expand strategy reruns with a larger one
    when fewer than m were found).

    Fills ``cands`` (m, n) float (integer-valued, sorted by cost), ``costs`` (m,) and, for the constrained modes,
    ``sols`` (m, k) with the inner solution of each candidate. Returns (status, nodes, n_found).
    """
    m, n = cands.shape
    acc = np.zeros((n + 1, n))  # acc[k, j] = sum_{i >= k} L[i, j] (z_i - zc_i), j < k
    dist = np.zeros(n)  # dist[k]: squared norm of levels k+1 .. n-1
    zc = np.empty(n)
    z = np.empty(n)
    step = np.empty(n)
    out = np.empty(sols.shape[1])
    for i in range(m):
        costs[i] = math.inf
    found = 0
    worst = 0
    chi2 = chi2_start
    k = n - 1
    zc[k] = zhat[k]
    z[k] = math.floor(zc[k] + 0.5)
    y = zc[k] - z[k]
    step[k] = 1.0 if y >= 0.0 else -1.0
    nodes = 0
    status = OK
    while True:
        nodes += 1
        if nodes > max_nodes:
            status = NOT_FINISHED
            break
        newdist = dist[k] + y * y / d[k]
        if newdist < chi2:
            if k > 0:
                e = z[k] - zc[k]
                for j in range(k):
                    acc[k, j] = acc[k + 1, j] + L[k, j] * e
                k -= 1
                dist[k] = newdist
                zc[k] = zhat[k] + acc[k + 1, k]
                z[k] = math.floor(zc[k] + 0.5)
                y = zc[k] - z[k]
                step[k] = 1.0 if y >= 0.0 else -1.0
                continue
            cost = _leaf_cost(mode, newdist, zhat, z, P, v, W, U, w, F, lengths, chi2, out)
            if cost < chi2:
                slot = found if found < m else worst
                for i in range(n):
                    cands[slot, i] = z[i]
                for i in range(out.shape[0]):
                    sols[slot, i] = out[i]
                costs[slot] = cost
                if found < m:
                    found += 1
                if found == m:
                    worst = 0
                    for i in range(1, m):
                        if costs[i] > costs[worst]:
                            worst = i
                    chi2 = costs[worst]
            z[0] += step[0]
            y = zc[0] - z[0]
            step[0] = -step[0] - (1.0 if step[0] > 0.0 else -1.0)
        else:
            if k == n - 1:
                break
            k += 1
            z[k] += step[k]
            y = zc[k] - z[k]
            step[k] = -step[k] - (1.0 if step[k] > 0.0 else -1.0)
    # sort by cost (insertion sort; m is small)
    for i in range(1, m):
        j = i
        while j > 0 and costs[j] < costs[j - 1]:
            costs[j], costs[j - 1] = costs[j - 1], costs[j]
            for q in range(n):
                cands[j, q], cands[j - 1, q] = cands[j - 1, q], cands[j, q]
            for q in range(sols.shape[1]):
                sols[j, q], sols[j - 1, q] = sols[j - 1, q], sols[j, q]
            j -= 1
    return status, nodes, found


@njit(cache=True)
def prepare(a, Q, L, d, Z, Zti, zhat):
    """Check, factorise and decorrelate; fill zhat = Z^T (a - shift). Returns (code, i, j, shift (n,) int64)."""
    n = a.shape[0]
    shift = np.empty(n, dtype=np.int64)
    for r in range(n):
        if not math.isfinite(a[r]):
            return ERR_NONFINITE, -1, r, shift
    code, i, j = check_matrix(Q)
    if code != OK:
        return code, i, j, shift
    bad = ltdl_into(Q, L, d)
    if bad >= 0:
        return ERR_NOT_PD, bad, 0, shift
    for r in range(n):
        for c in range(n):
            Z[r, c] = 1 if r == c else 0
            Zti[r, c] = 1 if r == c else 0
    reduce_into(L, d, Z, Zti)
    for r in range(n):
        shift[r] = np.int64(math.floor(a[r] + 0.5))
    for c in range(n):
        s = 0.0
        for r in range(n):
            s += Z[r, c] * (a[r] - shift[r])
        zhat[c] = s
    return OK, 0, 0, shift


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


_E1 = np.empty(0)
_E2 = np.empty((0, 0))


@njit(cache=True)
def prepare_new(a, Q):
    """:func:`prepare` into freshly allocated work arrays; returns (code, i, j, shift, L, d, Z, Zti, zhat)."""
    n = a.shape[0]
    L = np.empty((n, n))
    d = np.empty(n)
    Z = np.empty((n, n), dtype=np.int64)
    Zti = np.empty((n, n), dtype=np.int64)
    zhat = np.empty(n)
    code, i, j, shift = prepare(a, Q, L, d, Z, Zti, zhat)
    return code, i, j, shift, L, d, Z, Zti, zhat


@njit(cache=True)
def _ils_kernel(a, Q, m, max_nodes, e1, e2):
    n = a.shape[0]
    code, i, j, shift, L, d, Z, Zti, zhat = prepare_new(a, Q)
    cz = np.zeros((m, n))
    costs = np.full(m, math.inf)
    nodes = 0
    found = 0
    if code == OK:
        code, nodes, found = search_into(zhat, L, d, max_nodes, MODE_ILS, e2, e1, e2, e2, e1, e2, e1, cz, costs,
                                         np.empty((m, 0)))
    return code, i, j, back_transform(cz, Zti, shift), costs, Z, Zti, L, d, zhat, shift, nodes, found


@njit(cache=True)
def _ils_batch_kernel(A, Qs, m, max_nodes, e1, e2):
    K, n = A.shape
    cands = np.zeros((K, m, n), dtype=np.int64)
    costs = np.full((K, m), math.inf)
    status = np.zeros(K, dtype=np.int64)
    nodes = np.zeros(K, dtype=np.int64)
    dd = np.empty((K, n))
    err = np.zeros(3, dtype=np.int64)  # first bad epoch, i, j
    err[0] = -1
    L = np.empty((n, n))
    Z = np.empty((n, n), dtype=np.int64)
    Zti = np.empty((n, n), dtype=np.int64)
    zhat = np.empty(n)
    cz = np.zeros((m, n))
    sols = np.empty((m, 0))
    for k in range(K):
        d = dd[k]
        code, i, j, shift = prepare(A[k], Qs[k if Qs.shape[0] > 1 else 0], L, d, Z, Zti, zhat)
        if code != OK:
            status[k] = code
            if err[0] < 0:
                err[0], err[1], err[2] = k, i, j
            continue
        code, nodes[k], _ = search_into(zhat, L, d, max_nodes, MODE_ILS, e2, e1, e2, e2, e1, e2, e1, cz,
                                        costs[k], sols)
        status[k] = code
        cands[k] = back_transform(cz, Zti, shift)
    return cands, costs, status, nodes, dd, err


class ILSResult:
    """Integer least-squares solution of one problem.

    Attributes: ``candidates`` (n_cands, n) int64, best first; ``sqnorms`` (n_cands,) squared norms
    ``(a_hat - a)^T Q^-1 (a_hat - a)`` (inf where fewer candidates were found); ``status`` ("finished" or
    "not finished": the work cap was reached and the candidates are only the best found so far); ``nodes`` (search
    nodes visited); the decorrelation ``Z``, ``Zti`` (= Z^-T), ``L``, ``d`` (conditional variances of z, cycles^2),
    ``z_hat`` (Z^T (a_hat - shift)) and the integer ``shift`` (round(a_hat)) taken out before the search.
    """

    __slots__ = ("candidates", "sqnorms", "finished", "nodes", "Z", "Zti", "L", "d", "z_hat", "shift")

    def __init__(self, candidates, sqnorms, finished, nodes, Z, Zti, L, d, z_hat, shift):
        self.candidates, self.sqnorms, self.finished, self.nodes = candidates, sqnorms, finished, nodes
        self.Z, self.Zti, self.L, self.d, self.z_hat, self.shift = Z, Zti, L, d, z_hat, shift

    @property
    def status(self) -> str:
        return "finished" if self.finished else "not finished"

    @property
    def best(self):
        return self.candidates[0]

    @property
    def ratio(self) -> float:
        """sqnorm(2nd) / sqnorm(best), the ratio-test statistic (>= 1)."""
        return float(self.sqnorms[1] / self.sqnorms[0])

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
    _check_counts(n_cands, max_nodes)
    a, Qm = a_hat, Q
    if not (type(a) is np.ndarray and type(Qm) is np.ndarray and a.dtype == np.float64 and Qm.dtype == np.float64
            and a.ndim == 1 and a.size and Qm.shape == (a.size, a.size) and a.flags.c_contiguous
            and Qm.flags.c_contiguous):
        a, Qm = as_problem(a_hat, Q)  # converts, or raises naming the wrong shape
    code, i, j, cands, costs, Z, Zti, L, d, zhat, shift, nodes, _ = _ils_kernel(a, Qm, int(n_cands),
                                                                                int(max_nodes), _E1, _E2)
    if code < 0:
        raise_for_status(code, i, j)
    return ILSResult(cands, costs, code == OK, nodes, Z, Zti, L, d, zhat, shift)


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
    cands, costs, status, nodes, d, err = _ils_batch_kernel(A, Qs, int(n_cands), int(max_nodes), _E1, _E2)
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
        cands, costs, status, _, _, err = _ils_batch_kernel(A, Qs, n_cands, max_nodes, _E1, _E2)
        if err[0] >= 0:
            raise_for_status(int(status[err[0]]), int(err[1]), int(err[2]), what=f"[{int(idx[err[0]])}]")
        for r, k in enumerate(idx):
            out[k] = (cands[r], costs[r], bool(status[r] == OK))
    return out
