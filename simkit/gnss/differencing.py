"""Single and double differences between antennas and satellites, with their covariance.

Arrays follow the /gnss/obs layout: (M, A, S) per signal (epochs, antennas, satellites), NaN where not tracked.
Single differences are taken against a reference antenna (SD_a = x_a - x_ref), double differences against a
reference satellite per system (DD_a,s = SD_a,s - SD_a,ref(sys(s))); the reference satellite of each system and
epoch is the one with the highest elevation among those valid on every antenna. For one epoch,
:func:`dd_operator` gives the matrix D with DD = D x (x the (A*S,) undifferenced vector), so that the covariance
of the DDs is D diag(sigma^2) D^T for independent undifferenced errors.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError


class DifferencingInputError(InputError):
    """An array given to the differencing functions has the wrong shape (names the argument)."""


def _obs(x, what: str = "x") -> np.ndarray:
    """``x`` as a float (M, A, S) array, or a :class:`DifferencingInputError` naming ``what``."""
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 3:
        raise DifferencingInputError(f"{what}: shape {arr.shape}; expected (M, A, S) (epochs, antennas, satellites)")
    return arr


def systems_of(sat_ids) -> np.ndarray:
    """System letter per satellite ("G", "C", ...), (S,) array of str."""
    return np.array([str(s)[0] for s in sat_ids])


def single_difference(x: np.ndarray, ref_antenna: int = 0) -> np.ndarray:
    """Between-antenna single differences (M, A-1, S): every other antenna minus ``ref_antenna``."""
    x = _obs(x)
    if not 0 <= ref_antenna < x.shape[1]:
        raise DifferencingInputError(f"ref_antenna: {ref_antenna}; expected 0 .. {x.shape[1] - 1}")
    others = [a for a in range(x.shape[1]) if a != ref_antenna]
    return x[:, others, :] - x[:, ref_antenna:ref_antenna + 1, :]


def reference_satellites(elevation: np.ndarray, valid: np.ndarray, sat_ids) -> np.ndarray:
    """Reference satellite per epoch and satellite: (M, S) int index of the reference of that satellite's system.

    ``elevation`` (M, S) rad, ``valid`` (M, S) bool (tracked on every antenna, e.g. ``np.isfinite(x).all(1)``).
    Entries are -1 where the system has no valid satellite at that epoch.
    """
    sys = systems_of(sat_ids)
    m, s = elevation.shape
    ref = np.full((m, s), -1, dtype=np.int64)
    el = np.where(valid, elevation, -np.inf)
    for letter in np.unique(sys):
        cols = np.flatnonzero(sys == letter)
        best = cols[np.argmax(el[:, cols], axis=1)]
        ok = np.isfinite(el[np.arange(m), best])
        ref[np.ix_(ok, cols)] = best[ok, None]
    return ref


def double_difference(x: np.ndarray, ref_sat: np.ndarray, ref_antenna: int = 0) -> np.ndarray:
    """Double differences (M, A-1, S); NaN at each system's reference satellite and where untracked."""
    x = _obs(x)
    if np.shape(ref_sat) != (x.shape[0], x.shape[2]):
        raise DifferencingInputError(f"ref_sat: shape {np.shape(ref_sat)}; expected (M, S) = "
                                     f"{(x.shape[0], x.shape[2])} for x of shape (M, A, S) = {x.shape}")
    sd = single_difference(x, ref_antenna)
    m = np.arange(x.shape[0])[:, None]
    ref_vals = sd[m, :, np.clip(ref_sat, 0, None)].transpose(0, 2, 1)  # (M, A-1, S)
    dd = sd - ref_vals
    is_ref = (ref_sat == np.arange(x.shape[2])[None, :]) | (ref_sat < 0)
    return np.where(is_ref[:, None, :], np.nan, dd)


def dd_operator(ref_sat: np.ndarray, valid: np.ndarray, n_antennas: int, ref_antenna: int = 0):
    """Double-difference operator for one epoch.

    ``ref_sat`` (S,) from :func:`reference_satellites`, ``valid`` (S,) bool. Returns (D, antenna, sat): D (K, A*S)
    with DD = D @ x.reshape(-1) for x (A, S), and the antenna and satellite index of each of the K rows (rows
    ordered by antenna, then satellite).
    """
    ref_sat = np.asarray(ref_sat)
    s_count = ref_sat.shape[0]
    sats = np.flatnonzero(np.asarray(valid, dtype=bool) & (ref_sat >= 0) & (ref_sat != np.arange(s_count)))
    others = np.array([a for a in range(n_antennas) if a != ref_antenna], dtype=np.int64)
    d = dd_matrix(np.zeros(len(sats), dtype=np.int64), sats, ref_sat[sats], n_antennas, s_count, 1, ref_antenna)
    return d, np.repeat(others, len(sats)), np.tile(sats.astype(np.int64), len(others))


def dd_matrix(signal, sat, ref, n_ant: int, n_sat: int, n_sig: int = 1, ref_antenna: int = 0) -> np.ndarray:
    """D (r n, G A S) with DD = D x for x (G, A, S) flattened, for n channels (``signal``, ``sat``, ``ref`` (n,)
    int: signal, satellite and its reference satellite) on the r = A - 1 baselines from ``ref_antenna``; rows
    baseline-major (antennas in order, the reference left out), then channel."""
    n = len(sat)
    others = [a for a in range(n_ant) if a != ref_antenna]
    D = np.zeros((len(others), n, n_sig, n_ant, n_sat))
    c = np.arange(n)
    for k, ant in enumerate(others):
        for a, sign in ((ant, 1.0), (ref_antenna, -1.0)):
            np.add.at(D[k], (c, signal, a, sat), sign)
            np.add.at(D[k], (c, signal, a, ref), -sign)
    return D.reshape(len(others) * n, n_sig * n_ant * n_sat)


def dd_covariance(sigma: np.ndarray, ref_sat: np.ndarray, valid: np.ndarray, ref_antenna: int = 0):
    """Covariance of one epoch's double differences from undifferenced standard deviations ``sigma`` (A, S).

    Returns (Q (K, K), antenna (K,), sat (K,)) in the row order of :func:`dd_operator`.
    """
    d, ant, sat = dd_operator(ref_sat, valid, sigma.shape[0], ref_antenna)
    var = np.nan_to_num(np.asarray(sigma, dtype=float).reshape(-1) ** 2)
    return (d * var) @ d.T, ant, sat


@dataclass(frozen=True)
class FloatSolution:
    """Float solution of T epochs for r baselines: a_hat (T, r n) cycles, b_hat (T, 3 r) m, Qa, Qb, Qba."""

    a_hat: np.ndarray
    b_hat: np.ndarray
    Qa: np.ndarray
    Qb: np.ndarray
    Qba: np.ndarray


def _between_satellite_cofactor(n):
    """D D^T (n, n) of the between-satellite difference of n + 1 satellites: half the DD covariance of one antenna
    pair with unit undifferenced sigma (:func:`dd_covariance`), I + 1 1^T."""
    ref = np.zeros(n + 1, dtype=np.int64)  # satellite 0 is the reference; which one does not change D D^T
    Q, _, _ = dd_covariance(np.ones((2, n + 1)), ref, np.ones(n + 1, bool))
    return 0.5 * Q


def symmetric(P: np.ndarray) -> np.ndarray:
    """The symmetric part of a stack of matrices (..., n, n): removes the rounding asymmetry of a product."""
    return 0.5 * (P + np.swapaxes(P, -1, -2))


def dd_float(G, carrier_m, code_m, Q_carrier, Q_code, wavelength_m) -> FloatSolution:
    """Single-epoch DD float solution, batched over K epochs: the baseline from the code, the ambiguities from the
    carrier minus it (the carrier's free ambiguity per row leaves it no information on the baseline):

        b = (G' Qp^-1 G)^-1 G' Qp^-1 y_p,  a = L^-1 (y_phi - G b),
        Qb = (G' Qp^-1 G)^-1,  Qa = L^-1 (Qphi + G Qb G') L^-1,  Qba = -Qb G' L^-1,  L = diag(wavelength).

    ``G`` (K, N, B) m per m (DD range = G b); ``carrier_m``, ``code_m`` (K, N) m; ``Q_carrier``, ``Q_code``
    (K, N, N) m^2 DD covariances; ``wavelength_m`` (N,) or a scalar. Ambiguities in cycles, baselines in m.
    """
    lam = np.broadcast_to(np.asarray(wavelength_m, float), (G.shape[1],))
    GtW = np.swapaxes(np.linalg.solve(Q_code, G), 1, 2)  # G' Qp^-1
    Qb = symmetric(np.linalg.inv(GtW @ G))
    b_hat = np.einsum("kij,kj->ki", Qb @ GtW, code_m)
    a_hat = (carrier_m - np.einsum("kij,kj->ki", G, b_hat)) / lam
    GQb = G @ Qb
    Qa = symmetric((Q_carrier + GQb @ np.swapaxes(G, 1, 2)) / np.outer(lam, lam))
    return FloatSolution(a_hat, b_hat, Qa, Qb, -np.swapaxes(GQb, 1, 2) / lam)


def float_solution(G, carrier_cycles, code_m, wavelength_m, sigma_phase_m, sigma_code_m) -> FloatSolution:
    """:func:`dd_float` of single-epoch DD carrier and code of r baselines from one master antenna, each antenna's
    observations with the same undifferenced sigmas.

    ``G`` (T, n, 3): DD geometry rows of one baseline; ``carrier_cycles`` and ``code_m`` (T, r, n) DDs; sigmas
    of undifferenced observations (m). The DD noise of baseline k is D(e_k - e_master) with D the
    between-satellite difference, so Cov(DD_k, DD_l) = (1 + [k == l]) sigma^2 D D^T. Rows baseline-major.
    """
    T, n, _ = G.shape
    r = carrier_cycles.shape[1]
    S = np.eye(r) + np.ones((r, r))
    C = np.kron(S, _between_satellite_cofactor(n))[None]
    Gr = np.zeros((T, r * n, 3 * r))
    for k in range(r):
        Gr[:, k * n:(k + 1) * n, 3 * k:3 * k + 3] = G
    carrier = wavelength_m * carrier_cycles.reshape(T, r * n)
    return dd_float(Gr, carrier, code_m.reshape(T, r * n), np.broadcast_to(sigma_phase_m**2 * C, (T,) + C.shape[1:]),
                    np.broadcast_to(sigma_code_m**2 * C, (T,) + C.shape[1:]), wavelength_m)
