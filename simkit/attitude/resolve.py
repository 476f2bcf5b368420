"""Ambiguity resolution of a group of float epochs: ILS (LAMBDA), C-LAMBDA per baseline, MC-LAMBDA, with
validation (ratio test; fixed failure rate), partial fixing (LAMBDA) and the bootstrapped success rate per epoch.

Cycles for ambiguities, metres (ENU) for baselines. ``ratio`` = second-best cost / best cost (>= 1), the
squared norm for ILS and the constrained cost for C-/MC-LAMBDA.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import ambiguity as amb
from .dd import FloatGroup, symmetric
from .errors import AttitudeInputError

METHODS = ("lambda", "clambda", "mclambda")
VALIDATIONS = ("pf", "ratio", "ffrt", "none")


@dataclass(frozen=True)
class FixPolicy:
    """How fixes are searched and accepted. ``validation`` "pf": the ratio test, then only where the failure rate
    is proven <= ``pf`` (:func:`_hold_pf`); "ratio": accept when ratio >= ``ratio_threshold`` (0 accepts every
    finished search); "none": accept every finished search; "ffrt" (LAMBDA only): fixed-failure-rate ratio test,
    accept when best / 2nd <= mu with mu calibrated per epoch on its own Qa for the failure rate ``pf``
    (``ffrt_samples`` Monte Carlo draws; mu = 1 without draws where the lower bound of the ILS success rate is
    already >= 1 - pf). ``partial_p0`` (LAMBDA only): epochs that fail the test fix the largest decorrelated
    subset whose bootstrapped success rate is >= partial_p0. ``max_nodes``: the search's work cap."""

    ratio_threshold: float = 3.0
    partial_p0: float | None = None
    max_nodes: int = amb.DEFAULT_MAX_NODES
    validation: str = "pf"
    pf: float = 1e-3
    ffrt_samples: int = 10_000


@dataclass(frozen=True)
class Resolution:
    """Per epoch of a group (K epochs, r baselines, n channels per baseline).

    ``z`` (K, r n) float cycles, the best integer candidate (NaN for partial fixes); ``ratio`` (K,); ``accepted``
    (K,) bool; ``partial`` (K,) bool (a subset fixed); ``success_rate`` (K,) bootstrapped (of Qa, decorrelated);
    ``finished`` (K,) bool (the search completed within its work cap; ``bounded`` (K,) bool: the constrained
    search stopped once the ratio was known to pass, so ``ratio`` is a lower bound); ``b`` (K, 3 r) m ENU
    baselines given the fix (float where nothing was accepted); ``Qb`` (K, 3 r, 3 r) m^2; ``rotation`` (K, 3, 3) body -> ENU of
    MC-LAMBDA (NaN otherwise); ``z_check`` (K, p) the fixed combinations and ``Z`` (K, r n, p) the integer maps
    (z_check = Z' a for the true a when right) used to label wrong fixes, p = r n for full fixes;
    ``sr_bounds`` (K, 2) lower and upper bounds of the ILS success rate (pull-in regions, bootstrapping, ADOP
    volume); ``mu`` (K,) the fixed-failure-rate threshold on the ILS best / 2nd squared norm (validation ffrt; pf:
    where an epoch passed the ratio test; NaN elsewhere).
    """

    z: np.ndarray
    ratio: np.ndarray
    accepted: np.ndarray
    partial: np.ndarray
    success_rate: np.ndarray
    finished: np.ndarray
    b: np.ndarray
    Qb: np.ndarray
    rotation: np.ndarray
    z_check: list
    Z: list
    bounded: np.ndarray
    sr_bounds: np.ndarray
    mu: np.ndarray


def conditioned(grp: FloatGroup, z: np.ndarray):
    """Baselines (K, 3 r) and covariance (K, 3 r, 3 r) given integer ambiguities z (K, r n)."""
    K = np.swapaxes(np.linalg.solve(grp.Qa, np.swapaxes(grp.Qba, 1, 2)), 1, 2)  # Qba Qa^-1
    b = grp.b_hat - np.einsum("kij,kj->ki", K, grp.a_hat - z)
    Qb = grp.Qb - K @ np.swapaxes(grp.Qba, 1, 2)
    return b, symmetric(Qb)


def _search(grp: FloatGroup, method: str, F: np.ndarray, max_nodes: int, stop: float):
    """(best z (K, r n) int, ratio (K,), finished (K,), rotation (K, 3, 3) or NaN, bounded (K,)): constrained
    searches stop once the 2nd cost is known to be >= ``stop`` x the best (``bounded``: ratio is a lower bound)."""
    Kn, rn = grp.a_hat.shape
    r = F.shape[1]
    rot = np.full((Kn, 3, 3), np.nan)
    if method == "lambda":
        res = amb.ils_batch(grp.a_hat, grp.Qa, n_cands=2, max_nodes=max_nodes)
        return res.candidates[:, 0], res.sqnorms[:, 1] / res.sqnorms[:, 0], res.finished, rot, np.zeros(Kn, bool)
    if method == "clambda":
        n = rn // r
        z = np.zeros((Kn, rn), dtype=np.int64)
        ratio, finished, bounded = np.full(Kn, np.inf), np.ones(Kn, bool), np.zeros(Kn, bool)
        for k in range(r):
            a, s = slice(k * n, (k + 1) * n), slice(3 * k, 3 * k + 3)
            res = amb.baseline_constrained_ils(grp.a_hat[:, a], grp.Qa[:, a, a], grp.b_hat[:, s], grp.Qb[:, s, s],
                                               grp.Qba[:, s, a], np.linalg.norm(F[:, k]), n_cands=2,
                                               max_nodes=max_nodes, ratio_stop=stop)
            z[:, a] = res.candidates[:, 0]
            ratio = np.minimum(ratio, res.costs[:, 1] / res.costs[:, 0])
            finished &= res.finished
            bounded |= res.bounded
        return z, ratio, finished, rot, bounded
    res = amb.attitude_constrained_ils(grp.a_hat, grp.Qa, grp.b_hat, grp.Qb, grp.Qba, F, n_cands=2,
                                       max_nodes=max_nodes, ratio_stop=stop)
    return res.candidates[:, 0], res.costs[:, 1] / res.costs[:, 0], res.finished, res.rotations[:, 0], res.bounded


def resolve(grp: FloatGroup, method: str, F: np.ndarray, policy: FixPolicy = FixPolicy()) -> Resolution:
    """Fix the ambiguities of ``grp`` with ``method`` (one of :data:`METHODS`) under ``policy``; ``F`` (3, r)
    body baselines m."""
    validation, ratio_threshold, pf = policy.validation, policy.ratio_threshold, policy.pf
    if method not in METHODS:
        raise AttitudeInputError("method", f"{method!r}; expected one of {', '.join(METHODS)}")
    if validation not in VALIDATIONS or (validation == "ffrt" and method != "lambda"):
        raise AttitudeInputError("estimator.validation", f"{validation!r}; expected pf, ratio or none, or ffrt "
                                                         "(LAMBDA: the test is calibrated on the ILS ratio)")
    if validation == "none":
        ratio_threshold = 0.0
    stop = ratio_threshold if ratio_threshold > 0 and validation in ("ratio", "pf") else 1.0  # 1: stop once best is proven
    with np.errstate(divide="ignore", invalid="ignore"):  # an unfinished search has no 2nd cost: ratio NaN / inf
        z, ratio, finished, rot, bounded = _search(grp, method, np.asarray(F, float), policy.max_nodes, stop)
    sr, bounds = _success_rates(grp.Qa)
    mu = np.full(len(z), np.nan)
    if validation == "ffrt":
        mu = _ffrt_mu(grp.Qa, bounds[:, 0], pf, policy.ffrt_samples)
        accepted = finished & (1.0 / ratio <= mu)
    else:
        accepted = finished & ((ratio >= ratio_threshold) | (ratio_threshold <= 0))
        if validation == "pf":
            accepted, mu = _hold_pf(grp, method, z, ratio, accepted, bounds[:, 0], policy)
    b, Qb = conditioned(grp, z.astype(float))
    b = np.where(accepted[:, None], b, grp.b_hat)
    Qb = np.where(accepted[:, None, None], Qb, grp.Qb)
    zf = np.where(accepted[:, None], z.astype(float), np.nan)
    eye = np.eye(z.shape[1], dtype=np.int64)
    z_check = [z[i] if accepted[i] else z[i, :0] for i in range(len(z))]
    Zs = [eye if accepted[i] else eye[:, :0] for i in range(len(z))]
    partial = np.zeros(len(z), bool)
    if policy.partial_p0 is not None and method == "lambda":
        for i, (bi, Qbi, zi, Zi) in _partial(grp, policy.partial_p0, accepted):
            b[i], Qb[i], z_check[i], Zs[i], partial[i] = bi, Qbi, zi, Zi, True
    return Resolution(zf, ratio, accepted, partial, sr, finished, b, Qb, rot, z_check, Zs, bounded, bounds, mu)


def _ffrt_mu(Qa, lower, pf, n_samples):
    """FF-ratio threshold mu (K,): 1 where the ILS failure rate is proven <= pf, Monte Carlo calibrated elsewhere
    (seeded by the epoch count: deterministic)."""
    mu = np.ones(len(Qa))
    need = np.flatnonzero(~(1.0 - lower <= pf))
    if need.size:
        mu[need] = amb.ffrt_thresholds(Qa[need], pf, n_samples, seed=len(Qa))
    return mu


def _hold_pf(grp, method, z, ratio, passed, lower, policy):
    """(accepted (K,), mu (K,)) of validation "pf": of the epochs that ``passed`` the method's own ratio test, keep
    those whose ILS failure rate is proven <= ``pf``, by the lower bound ``lower`` (K,) of the ILS success rate
    (mu = 1) or else by the fixed-failure-rate test on the ILS ratio (mu calibrated on the epoch's Qa, only for
    these epochs: cheap where few pass). A C-/MC-LAMBDA fix is kept only where it equals the ILS fix and the ILS
    ratio passes ``threshold`` too: then it is wrong only where ILS is, so P(wrong and accepted) <= P(ILS wrong and
    accepted) <= pf for all three methods, and no more epochs are calibrated than for LAMBDA. The decision reads
    the float solution only (never the truth)."""
    pf, n_samples, threshold = policy.pf, policy.ffrt_samples, policy.ratio_threshold
    mu, accepted = np.full(len(z), np.nan), np.zeros(len(z), bool)
    idx = np.flatnonzero(passed)
    if idx.size == 0:
        return accepted, mu
    if method == "lambda":
        same, best_over_2nd = np.ones(idx.size, bool), 1.0 / ratio[idx]
    else:
        ils = amb.ils_batch(grp.a_hat[idx], grp.Qa[idx], n_cands=2, max_nodes=policy.max_nodes)
        with np.errstate(divide="ignore", invalid="ignore"):
            best_over_2nd = ils.sqnorms[:, 0] / ils.sqnorms[:, 1]
        same = ils.finished & np.all(ils.candidates[:, 0] == z[idx], axis=1) & (best_over_2nd * threshold <= 1)
    idx, best_over_2nd = idx[same], best_over_2nd[same]
    mu[idx] = _ffrt_mu(grp.Qa[idx], lower[idx], pf, n_samples)
    accepted[idx] = best_over_2nd <= mu[idx]
    return accepted, mu


def _success_rates(Qa: np.ndarray):
    """Bootstrapped success rate (K,) after decorrelation and the ILS success-rate bounds (K, 2) [lower, upper]."""
    b = amb.ils_success_bounds(Qa)
    return b["bootstrap"], np.stack([b["lower"], b["upper"]], axis=-1)


def _partial(grp, p0, accepted):
    """Partial fixes of the rejected epochs: yields (epoch, (baseline conditioned on the fixed combinations,
    its covariance, the fixed combinations, their integer map))."""
    for i in np.flatnonzero(~accepted):
        pf = amb.partial_fix(grp.a_hat[i], grp.Qa[i], p0=p0)
        if pf.n_fixed == 0:
            continue
        Z = pf.Z_fixed.astype(float)
        Qz = Z.T @ grp.Qa[i] @ Z
        K = grp.Qba[i] @ Z @ np.linalg.inv(Qz)
        yield i, (grp.b_hat[i] - K @ (Z.T @ grp.a_hat[i] - pf.z_fixed), grp.Qb[i] - K @ Z.T @ grp.Qba[i].T,
                  pf.z_fixed, pf.Z_fixed)


def subset(grp: FloatGroup, idx: np.ndarray) -> FloatGroup:
    """The epochs ``idx`` (indices into the group) of ``grp``."""
    return FloatGroup(grp.epochs[idx], grp.signal, grp.sat, grp.ref, *(getattr(grp, f)[idx] for f in
                      ("a_hat", "Qa", "b_hat", "Qb", "Qba", "G", "Qphi")),
                      None if grp.Qphi_correlated is None else grp.Qphi_correlated[idx])


def _first_fixes(grp, breaks, method, F, policy):
    """Search run by run (a run: epochs between continuity breaks) until each run has an accepted fix; chunks
    double (1, 2, 4, ... epochs per run) so a run that never fixes costs O(log) calls. Returns (searched
    {epoch: (Resolution, row)}, first accepted epoch per run or -1, run id per epoch)."""
    run = np.cumsum(breaks) - 1
    starts, ends = np.flatnonzero(breaks), np.append(np.flatnonzero(breaks)[1:], len(breaks))
    first = np.full(len(starts), -1)
    pos, step, searched = starts.copy(), 1, {}
    pending = np.arange(len(starts))
    while pending.size:
        idx = np.concatenate([np.arange(pos[q], min(pos[q] + step, ends[q])) for q in pending])
        res = resolve(subset(grp, idx), method, F, policy)
        for row, i in enumerate(idx):
            searched[i] = (res, row)
        acc = idx[res.accepted]
        for q in pending:
            hit = acc[(acc >= pos[q]) & (acc < ends[q])]
            first[q] = hit.min() if hit.size else -1
        pos[pending] += step
        pending = pending[(first[pending] < 0) & (pos[pending] < ends[pending])]
        step *= 2
    return searched, first, run


def resolve_held(grp: FloatGroup, method: str, F: np.ndarray, breaks: np.ndarray,
                 policy: FixPolicy = FixPolicy()) -> Resolution:
    """:func:`resolve` with ambiguity continuity: after the first accepted fix of a run of epochs without a
    break (``breaks`` (K,) bool: a gap in the epochs or a loss-of-lock flag on any channel used), the later
    epochs of the run keep that fix (their ``ratio`` is NaN: not searched). Epochs before it are searched."""
    searched, first, run = _first_fixes(grp, np.asarray(breaks, bool), method, F, policy)
    K = len(run)
    fields = {f: [] for f in ("z", "ratio", "accepted", "partial", "finished", "rotation", "bounded", "mu")}
    z_check, Zs, b, Qb = [None] * K, [None] * K, grp.b_hat.copy(), grp.Qb.copy()
    held = (first[run] >= 0) & (np.arange(K) > first[run])
    zh = np.zeros(grp.a_hat.shape)
    for i in range(K):
        src, row = searched[first[run[i]]] if held[i] else searched[i]
        for f in fields:
            fields[f].append(getattr(src, f)[row])
        z_check[i], Zs[i] = src.z_check[row], src.Z[row]
        zh[i] = src.z[row]
        if not held[i]:
            b[i], Qb[i] = src.b[row], src.Qb[row]
    if held.any():
        bh, Qh = conditioned(subset(grp, held), zh[held])
        b[held], Qb[held] = bh, Qh
    out = {f: np.array(v) for f, v in fields.items()}
    out["ratio"][held] = np.nan
    out["rotation"][held] = np.nan
    out["mu"][held] = np.nan
    sr, bounds = _success_rates(grp.Qa)
    return Resolution(out["z"], out["ratio"], out["accepted"], out["partial"], sr, out["finished"], b, Qb,
                      out["rotation"], z_check, Zs, out["bounded"], bounds, out["mu"])
