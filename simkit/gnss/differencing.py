"""Single and double differences between antennas and satellites, with their covariance.

Arrays follow the /gnss/obs layout: (M, A, S) per signal (epochs, antennas, satellites), NaN where not tracked.
Single differences are taken against a reference antenna (SD_a = x_a - x_ref), double differences against a
reference satellite per system (DD_a,s = SD_a,s - SD_a,ref(sys(s))); the reference satellite of each system and
epoch is the one with the highest elevation among those valid on every antenna. For one epoch,
:func:`dd_operator` gives the matrix D with DD = D x (x the (A*S,) undifferenced vector), so that the covariance
of the DDs is D diag(sigma^2) D^T for independent undifferenced errors.
"""
from __future__ import annotations

import numpy as np

from ..errors import SimkitError


class DifferencingInputError(SimkitError, ValueError):
    """An array given to the differencing functions has the wrong shape (names the argument)."""

    exit_code = 2


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
    s_count = ref_sat.shape[0]
    sats = [s for s in range(s_count) if valid[s] and ref_sat[s] >= 0 and ref_sat[s] != s]
    others = [a for a in range(n_antennas) if a != ref_antenna]
    d = np.zeros((len(others) * len(sats), n_antennas * s_count))
    ant_idx, sat_idx = [], []
    row = 0
    for a in others:
        for s in sats:
            r = ref_sat[s]
            d[row, a * s_count + s] += 1.0
            d[row, ref_antenna * s_count + s] -= 1.0
            d[row, a * s_count + r] -= 1.0
            d[row, ref_antenna * s_count + r] += 1.0
            ant_idx.append(a)
            sat_idx.append(s)
            row += 1
    return d, np.array(ant_idx, dtype=np.int64), np.array(sat_idx, dtype=np.int64)


def dd_covariance(sigma: np.ndarray, ref_sat: np.ndarray, valid: np.ndarray, ref_antenna: int = 0):
    """Covariance of one epoch's double differences from undifferenced standard deviations ``sigma`` (A, S).

    Returns (Q (K, K), antenna (K,), sat (K,)) in the row order of :func:`dd_operator`.
    """
    d, ant, sat = dd_operator(ref_sat, valid, sigma.shape[0], ref_antenna)
    var = np.nan_to_num(np.asarray(sigma, dtype=float).reshape(-1) ** 2)
    return (d * var) @ d.T, ant, sat
