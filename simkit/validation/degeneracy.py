"""Degenerate geometry, decided from the geometry alone (never from the Gramian whose rank is being tested).

For a subset of k satellites the DD lines of sight span the range of the scatter G (see
:func:`simkit.validation.gramian.los_scatter`), whatever the reference satellite. With H rows (s x b)^T:

- dual antenna (baseline b): every row is orthogonal to b, so rank <= 2; rank = min(k - 1, 2) unless the DD lines
  of sight, projected on the plane orthogonal to b, span less: one DD parallel to b (k = 2), or all DDs in one
  plane containing b (k >= 3).
- three antennas (b1, b2 not collinear, plane normal n): rank 2 for k = 2 unless the DD lies in the baseline
  plane; rank 3 for k >= 3 unless all DDs are collinear or all lie in the baseline plane.

Each test is a scale-free angle (rad): sqrt(eigenvalue ratio) of the relevant projected scatter over trace(G).
Geometry within :data:`DEGENERACY_TOL_RAD` of a degenerate one is reported as degenerate: there the smallest
singular value of L falls towards the rank threshold (``RANK_RTOL`` 1e-12 of sigma_max); above it, it stays at
~(1e-3)^2 x (baseline ratio)^2 x (DD length ratio)^2 >~ 1e-9 of sigma_max, well clear of the threshold.
"""
from __future__ import annotations

import numpy as np

from .jacobi import sym_eig3

DEGENERACY_TOL_RAD = 1e-3

REASONS = {
    0: "non-degenerate",
    1: "coincident lines of sight (no DD direction)",
    2: "DD line of sight parallel to the baseline",
    3: "DD lines of sight coplanar with the baseline",
    4: "DD line of sight in the plane of the baselines",
    5: "DD lines of sight collinear",
    6: "DD lines of sight all in the plane of the baselines",
    7: "collinear baselines",
}


def expected_rank(n_baselines: int, k) -> np.ndarray:
    """Rank of L for non-degenerate geometry (claims C4, C5): dual 1 (k = 2) or 2; three antennas 2 or 3."""
    k = np.asarray(k)
    return np.where(k <= 2, n_baselines, n_baselines + 1)


def _ratio_angle(num, tr):
    return np.sqrt(np.clip(num, 0.0, None) / np.where(tr > 0, tr, 1.0))


def _eigvals(G):
    """Eigenvalues (N, 3) of symmetric PSD matrices, descending (Jacobi; round-off negatives sort last)."""
    return sym_eig3(np.ascontiguousarray(G))[0]


def _projected_eig(G, P):
    """Eigenvalues (descending) of P G P for a fixed projector P (3, 3)."""
    return _eigvals(P @ G @ P)


def classify(G, k, baselines_b) -> tuple[np.ndarray, np.ndarray]:
    """Degeneracy margin (N,) rad and reason code (N,) int (see :data:`REASONS`, 0 = non-degenerate) of scatters
    ``G`` (N, 3, 3) of subsets of ``k`` (N,) satellites, for one or two ``baselines_b`` (B, 3) m."""
    G = np.asarray(G, float)
    k = np.broadcast_to(np.asarray(k), G.shape[:1])
    b = np.asarray(baselines_b, float)
    tr = np.trace(G, axis1=-2, axis2=-1)
    if len(b) == 1:
        bh = b[0] / np.linalg.norm(b[0])
        lam = _projected_eig(G, np.eye(3) - np.outer(bh, bh))
        margin = _ratio_angle(np.where(k <= 2, lam[..., 0], lam[..., 1]), tr)
        code = np.where(margin < DEGENERACY_TOL_RAD, np.where(k <= 2, 2, 3), 0)
    else:
        n = np.cross(b[0], b[1])
        sin_b = np.linalg.norm(n) / (np.linalg.norm(b[0]) * np.linalg.norm(b[1]))
        if sin_b < DEGENERACY_TOL_RAD:
            return np.full(G.shape[:1], sin_b), np.full(G.shape[:1], 7)
        n = n / np.linalg.norm(n)
        out_of_plane = _ratio_angle(np.einsum("i,...ij,j->...", n, G, n), tr)
        spread = _ratio_angle(_eigvals(G)[..., 1], tr)               # second largest eigenvalue
        line = (k > 2) & (spread < out_of_plane)
        margin = np.where(line, spread, out_of_plane)
        code = np.where(margin < DEGENERACY_TOL_RAD, np.where(line, 5, np.where(k <= 2, 4, 6)), 0)
    tiny = tr < DEGENERACY_TOL_RAD**2
    return np.where(tiny, 0.0, margin), np.where(tiny, 1, code)
