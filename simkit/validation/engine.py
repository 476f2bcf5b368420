"""The validation run: every configuration, every satellite count, every epoch; claims C1-C7 tallied.

Subsets: ``highest`` (the k highest satellites, k = 2..visible) and ``n_random`` independent random orderings
(k random visible satellites); ``all`` is the highest subset with k = the visible count (the paper's Figs 2-5).
Epochs are processed in chunks so memory stays bounded (about 4 kB per epoch and configuration).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import checks
from .degeneracy import classify, expected_rank
from .gramian import design_matrix, gramian_from_scatter
from .observability import RANK_RTOL, atdop_from_svd, observable_degree_from_svd, rank_from_svd, svd
from .subsets import cumulative_scatter, ordering

C3_PER_CHUNK = 32      # epochs per chunk and satellite count on which Theorem 2 is re-checked with a random R
C1_DEFICIENT_PER_CHUNK = 512   # rank-deficient rows per chunk checked against numpy's pseudo-inverse
MAX_EXAMPLES = 5


@dataclass
class Group:
    """One configuration x subset kind: per epoch m and size index j (k = j + 2) the results."""

    config: str
    kind: str
    order: np.ndarray            # (M, S) satellite order; subset k = order[:, :k]
    valid: np.ndarray            # (M, K) k <= visible count
    rank: np.ndarray             # (M, K)
    atdop: np.ndarray            # (M, K, 3)
    degree: np.ndarray           # (M, K, 3)
    code: np.ndarray             # (M, K) degeneracy reason, 0 = none
    tallies: dict = field(default_factory=dict)


def _tally(group: Group, claim: str) -> dict:
    return group.tallies.setdefault(claim, {"checked": 0, "failed": 0, "degenerate": 0, "examples": []})


def _plain(v):
    """JSON-ready: arrays to lists, numpy scalars to Python, non-finite numbers to None ("unobservable")."""
    a = np.asarray(v, dtype=float)
    out = np.where(np.isfinite(a), a, np.nan).tolist()
    return [None if x != x else x for x in out] if a.ndim else (None if out != out else out)


def _example(geo, group: Group, m: int, j: int, **extra) -> dict:
    k = j + 2
    out = {"t_s": float(geo.t[m]), "k": k, "satellites": [geo.sat_ids[s] for s in group.order[m, :k]]}
    out.update({key: (v if isinstance(v, (int, str)) else _plain(v)) for key, v in extra.items()})
    return out


def _record(geo, group, claim, m_idx, j_idx, fail, nondeg, values=None):
    """Add checked/failed counts of rows (m_idx, j_idx) with ``fail`` (N,) bool to ``claim``'s tally."""
    t = _tally(group, claim)
    t["checked"] += int(nondeg.sum())
    t["degenerate"] += int((~nondeg).sum())
    bad = np.flatnonzero(fail & nondeg)
    t["failed"] += bad.size
    for r in bad[:max(0, MAX_EXAMPLES - len(t["examples"]))]:
        m, j = int(m_idx[r]), int(j_idx[r])
        t["examples"].append(_example(geo, group, m, j, rank=int(group.rank[m, j]), atdop=group.atdop[m, j],
                                      degree=group.degree[m, j], **({} if values is None else {"value": values[r]})))


def _chunk(geo, group, baselines, weighting, rows, k_max, rng):
    """Evaluate epochs ``rows`` (slice) of ``group``: Gramians, SVD, ranks, ATDOP, degrees, C1-C5 tallies."""
    G = cumulative_scatter(geo.los_b[rows], group.order[rows], k_max, weighting)
    valid = group.valid[rows]
    m_idx, j_idx = np.nonzero(valid)
    Gv = G[m_idx, j_idx]
    k = j_idx + 2
    L = gramian_from_scatter(Gv, baselines, weighting)
    sigma, U = svd(L)
    m_abs = m_idx + rows.start
    group.rank[m_abs, j_idx] = rnk = rank_from_svd(sigma)
    group.atdop[m_abs, j_idx] = atd = atdop_from_svd(sigma, U)
    group.degree[m_abs, j_idx] = deg = observable_degree_from_svd(sigma, U)
    margin, code = classify(Gv, k, baselines)
    group.code[m_abs, j_idx] = code
    nondeg = code == 0
    c1 = _c1_rows(sigma, rng)
    rel, allow = checks.c1_error(L[c1], sigma[c1], atd[c1])
    _record(geo, group, "C1", m_abs[c1], j_idx[c1], rel > allow, nondeg[c1], rel)
    rel2 = checks.c2_error(L, deg)
    _record(geo, group, "C2", m_abs, j_idx, rel2 > 1e-9, nondeg, rel2)
    claim = "C4" if len(baselines) == 1 else "C5"
    _record(geo, group, claim, m_abs, j_idx, rnk != expected_rank(len(baselines), k), nondeg)
    _c3(geo, group, baselines, rows, m_idx, j_idx, nondeg, rng)


def _c1_rows(sigma, rng) -> np.ndarray:
    """Rows for C1: every full-rank one (LU inverse, cheap) and up to C1_DEFICIENT_PER_CHUNK rank-deficient ones
    drawn at random (their reference is an SVD pseudo-inverse, the slow part)."""
    deficient = np.flatnonzero(sigma[:, -1] <= RANK_RTOL * sigma[:, 0])
    keep = np.ones(len(sigma), bool)
    if deficient.size > C1_DEFICIENT_PER_CHUNK:
        keep[deficient] = False
        keep[rng.choice(deficient, C1_DEFICIENT_PER_CHUNK, replace=False)] = True
    return keep


def _c3(geo, group, baselines, rows, m_idx, j_idx, nondeg, rng):
    """Theorem 2 on up to C3_PER_CHUNK rows per satellite count, with explicit DD design matrices."""
    for j in np.unique(j_idx):
        pick = np.flatnonzero(j_idx == j)
        pick = rng.choice(pick, size=min(C3_PER_CHUNK, pick.size), replace=False)
        m_abs = m_idx[pick] + rows.start
        e = np.take_along_axis(geo.los_b[m_abs], group.order[m_abs, :j + 2, None], axis=1)
        H = design_matrix(e[:, 1:] - e[:, :1], baselines)
        _record(geo, group, "C3", m_abs, j_idx[pick], ~checks.c3_agree(H, rng), nondeg[pick])


def run_group(geo, config, baselines, kind, weighting, rng, chunk=8192, progress=None) -> Group:
    """One configuration and subset kind over all epochs; ``progress`` a tqdm bar advanced per chunk."""
    order = ordering(geo.elevation, geo.visible, "highest" if kind == "highest" else "random", rng)
    nvis = geo.visible.sum(axis=1)
    k_max = max(2, int(nvis.max()))
    M, K = len(geo.t), k_max - 1
    valid = (np.arange(2, k_max + 1)[None, :] <= nvis[:, None])
    g = Group(config, kind, order, valid, np.zeros((M, K), int), np.full((M, K, 3), np.nan),
              np.full((M, K, 3), np.nan), np.zeros((M, K), int))
    for start in range(0, M, chunk):
        _chunk(geo, g, baselines, weighting, slice(start, min(M, start + chunk)), k_max, rng)
        if progress is not None:
            progress.update(1)
    _c6(geo, g)
    return g


def _c6(geo, g: Group):
    """C6 per epoch and satellite count, non-degenerate rows only; counter-examples the worst violations."""
    m_idx, j_idx = np.nonzero(g.valid & (g.code == 0))
    applicable, held, worst = checks.c6_epochs(g.atdop[m_idx, j_idx], g.degree[m_idx, j_idx])
    t = g.tallies["C6"] = {"checked": int(applicable.sum()), "held": int((applicable & held).sum()),
                           "per_k": {}, "examples": []}
    for j in np.unique(j_idx):
        sel = (j_idx == j) & applicable
        t["per_k"][int(j + 2)] = [int(sel.sum()), int((sel & held).sum())]
    bad = np.flatnonzero(applicable & ~held)
    for r in bad[np.argsort(-worst[bad])][:MAX_EXAMPLES]:
        m, j = int(m_idx[r]), int(j_idx[r])
        t["examples"].append(_example(geo, g, m, j, atdop=g.atdop[m, j], degree=g.degree[m, j]))


def c7(geo, g: Group, all_visible: bool = False) -> dict:
    """C7 for each satellite count and angle over all pairs of non-degenerate epochs (``all_visible``: only
    the rows whose k is the epoch's visible count, i.e. the paper's grouping by visible satellites)."""
    nvis = geo.visible.sum(axis=1)
    out = {"comparable": 0, "held": 0, "per_k": {}, "examples": []}
    for j in range(g.valid.shape[1]):
        rows = g.valid[:, j] & (g.code[:, j] == 0) & (~all_visible | (nvis == j + 2))
        for a, name in enumerate(("pitch", "roll", "yaw")):
            m = np.flatnonzero(rows & np.isfinite(g.atdop[:, j, a]))
            if m.size < 2:
                continue
            comp, held, ex = checks.c7_pairs(g.atdop[m, j, a], g.degree[m, j, a])
            out["comparable"] += comp
            out["held"] += held
            out["per_k"].setdefault(j + 2, {})[name] = [comp, held]
            if ex is not None:
                out["examples"].append({"angle": name, "pair": [
                    _example(geo, g, int(m[i]), j, atdop=g.atdop[m[i], j, a], degree=g.degree[m[i], j, a])
                    for i in ex]})
    out["examples"] = out["examples"][:MAX_EXAMPLES]
    return out
