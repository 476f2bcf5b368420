"""Code-based single-point positioning with Doppler velocity (weighted least squares, all epochs at once).

Model per satellite s at epoch k (one signal per satellite, the first tracked in the order given):
    P + c dT^s - GD^s - T(el) = |r^s - r| + w_e (x^s y - y^s x) / c + c dt_sys(s) + e
    -lambda D + c dT^s' - e_s . v^s - w_e (v^s_x y - v^s_y x) / c = -e_s . v + c dt'
with r^s, dT^s the file's satellite position at emission and clock (RTKLIB's satposs convention, the Sagnac term
added here), GD the code group delay of ``/gnss/group_delay``, T the Saastamoinen slant delay of
:mod:`simkit.gnss.atmosphere`, one receiver clock per system (G, C, ...), one clock drift. With broadcast
Klobuchar coefficients (``iono_coefficients``, from ``/gnss/iono_alpha``/``iono_beta``) the code is also corrected
for the broadcast ionospheric delay I(el, az) (f_ref/f)^2 of :func:`simkit.gnss.atmosphere.broadcast_ionosphere`
(P - I on the left); without them the ionosphere is not modelled, which biases the fix by metres. Satellite
velocity and clock drift are central differences of the stored epochs (second order at the ends); the receiver's
own Sagnac-rate term (w_e (x^s v_y - y^s v_x) / c, under 1 mm/s) is left out. Weights sin^2(el) / sigma^2; the
covariance is sigma^2 (A^T W A)^-1 with the a-priori ``sigma_code_m`` and ``sigma_doppler_m_per_s``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..constellation.geometry import angles_from_enu
from ..earth import C_LIGHT, OMEGA_E
from ..errors import InputError
from ..frames import ecef_to_enu_matrix, ecef_to_lla
from .atmosphere import broadcast_ionosphere, model_system, reference_frequency, troposphere


class SppInputError(InputError):
    """Arrays of the wrong shape or broadcast coefficients the model cannot use (CLI exit 2)."""


@dataclass(frozen=True)
class SppFixes:
    """``t`` (M,) s; ``pos_ecef`` (M, 3) m and ``vel_enu`` (M, 3) m/s of the antenna (NaN where no fix);
    ``pos_cov_enu`` (M, 3, 3) m^2, ``vel_cov_enu`` (M, 3, 3) (m/s)^2; ``clock`` (M, n_sys) m per system in
    ``systems``; ``n_sats`` (M,) satellites used; ``ionosphere`` the ionospheric correction applied."""

    t: np.ndarray
    pos_ecef: np.ndarray
    vel_enu: np.ndarray
    pos_cov_enu: np.ndarray
    vel_cov_enu: np.ndarray
    clock: np.ndarray
    systems: tuple
    n_sats: np.ndarray
    ionosphere: str = "none"


def ranges_and_lines_of_sight(r, sat):
    """Ranges with the Sagnac term (M, S) and unit line-of-sight vectors receiver->satellite (M, S, 3)."""
    d = sat - r[:, None, :]
    rho = np.linalg.norm(d, axis=-1)
    sag = OMEGA_E * (sat[..., 0] * r[:, None, 1] - sat[..., 1] * r[:, None, 0]) / C_LIGHT
    with np.errstate(invalid="ignore", divide="ignore"):  # satellites without an orbit: NaN, never used
        return rho + sag, d / rho[..., None]


def _elevation(r, e):
    """Elevation and azimuth (clockwise from north) (M, S) rad of the lines of sight ``e``, and the receiver's
    geodetic lat, lon, h (M, 3)."""
    lla = ecef_to_lla(r)
    el, az = angles_from_enu(np.einsum("mij,msj->msi", ecef_to_enu_matrix(lla[:, 0], lla[:, 1]), e))
    return el, az, lla


@dataclass(frozen=True)
class _Delays:
    """Atmospheric code corrections: broadcast Klobuchar ``iono`` ({system: (alpha, beta)} or None) scaled to each
    satellite's signal by ``iono_scale`` (S,), at GPS seconds of week ``gps_sow`` (M,); ``systems`` (S,)."""

    iono: dict | None
    iono_scale: np.ndarray
    gps_sow: np.ndarray | None
    systems: np.ndarray

    def rows(self, idx) -> "_Delays":
        """The same model at the epochs ``idx`` only."""
        return self if self.gps_sow is None else _Delays(self.iono, self.iono_scale, self.gps_sow[idx], self.systems)

    def __call__(self, lla, el, az):
        """Slant troposphere plus broadcast ionosphere (M, S) m."""
        el = np.clip(el, 0.05, None)
        lat, lon = lla[:, None, 0], lla[:, None, 1]
        out = troposphere(lat, np.clip(lla[:, None, 2], -500, 1e5), el)
        for sys, (alpha, beta) in (self.iono or {}).items():
            cols = self.systems == sys
            if cols.any():
                out[:, cols] += self.iono_scale[cols] * broadcast_ionosphere(
                    sys, alpha, beta, lat, lon, az[:, cols], el[:, cols], self.gps_sow[:, None])
        return out


def _solve(a, y, w, mask):
    """Batched weighted least squares; rows with ``mask`` False carry no weight. Returns (x, N^-1, ok): ok False
    where the normal matrix is singular (its smallest eigenvalue under 1e-12 of its largest)."""
    a = np.where(mask[..., None], a, 0.0)  # a satellite without an orbit has NaN geometry: no weight, no NaN
    y = np.where(mask, y, 0.0)
    aw = a * np.where(mask, w, 0.0)[..., None]
    n = np.swapaxes(aw, 1, 2) @ a
    n = n + np.einsum("mi,ij->mij", (np.einsum("mii->mi", n) == 0.0) * 1.0, np.eye(a.shape[-1]))  # a clock unseen
    eig = np.linalg.eigvalsh(n)
    ok = eig[:, 0] > 1e-12 * eig[:, -1]
    n[~ok] = np.eye(a.shape[-1])
    ninv = np.linalg.inv(n)
    return (ninv @ (np.swapaxes(aw, 1, 2) @ y[..., None]))[..., 0], ninv, ok


def _position(code, sat, sys_onehot, mask_rad, sigma, iterations, delays):
    """Position and clocks (M, 3 + n_sys) by Gauss-Newton. Every ``COARSE``-th epoch starts from the Earth's
    centre and takes ``iterations`` steps (the atmosphere, mask and weights from the fourth on); every epoch then
    starts from the nearest coarse fix and iterates, the atmosphere included, until its step is under 0.1 mm
    (at most ``iterations`` steps): a tenth of the work of starting every epoch from the centre."""
    m = len(code)
    coarse = np.arange(0, m, COARSE)
    xc, _, _, used, _, ok = _iterate(code[coarse], sat[coarse], sys_onehot, mask_rad, sigma, iterations,
                                     delays.rows(coarse), 0)
    good = np.flatnonzero(_enough(ok, used, sys_onehot))
    x0 = np.zeros((m, xc.shape[1]))
    if good.size:
        nearest = np.clip(np.searchsorted(coarse[good], np.arange(m) - COARSE // 2), 0, good.size - 1)
        x0 = xc[good][nearest]
    return _iterate(code, sat, sys_onehot, mask_rad, sigma, iterations, delays, 3 if good.size else 0, x0)


COARSE = 60


def _enough(ok, used, sys_onehot):
    """(M,) bool: a regular fix with at least as many satellites ``used`` (M, S) as unknowns (3 + the clocks of the
    systems seen at the epoch)."""
    return ok & (used.sum(1) >= 3 + (sys_onehot[None] * used[..., None]).any(1).sum(1))


def _iterate(code, sat, sys_onehot, mask_rad, sigma, iterations, delays, first, x=None):
    """Gauss-Newton steps from ``x`` (zeros: the Earth's centre); step ``it`` >= 3 - ``first`` models the
    atmosphere, the mask and the weights. Epochs whose step is under 0.1 mm stop iterating."""
    m, s = code.shape
    x = np.zeros((m, 3 + sys_onehot.shape[1])) if x is None else x.copy()
    e, el = np.zeros((m, s, 3)), np.zeros((m, s))
    used, ninv, ok = np.isfinite(code), np.tile(np.eye(x.shape[1]), (m, 1, 1)), np.zeros(m, bool)
    active = np.arange(m)
    for it in range(first, first + iterations):
        xa = x[active]
        with np.errstate(invalid="ignore", divide="ignore"):
            rho, ea = ranges_and_lines_of_sight(xa[:, :3], sat[active])
        ea = np.nan_to_num(ea)  # a satellite without a state (unhealthy) sits at the origin, as the receiver at first
        ela, az, lla = _elevation(xa[:, :3], ea)
        late = it >= 3
        atm = delays.rows(active)(lla, ela, az) if late else 0.0
        ua = np.isfinite(code[active]) & ((ela >= mask_rad) if late else True)
        y = np.nan_to_num(code[active] - atm - rho - xa[:, 3:] @ sys_onehot.T)
        a = np.concatenate([-ea, np.broadcast_to(sys_onehot, (len(active), s, sys_onehot.shape[1]))], axis=-1)
        w = (np.clip(np.sin(ela), 0.1, 1.0) ** 2 if late else np.ones((len(active), s))) / sigma**2
        dx, ni, oka = _solve(a, y, w, ua)
        x[active] = xa + dx
        e[active], el[active], used[active], ninv[active], ok[active] = ea, ela, ua, ni, oka
        if late:
            active = active[~(np.abs(dx).max(1) < 1e-4)]
            if active.size == 0:
                break
    return x, e, el, used, ninv, ok


def _delays(systems, wavelength_m, iono_coefficients, gps_sow, m) -> _Delays:
    if iono_coefficients is None:
        return _Delays(None, np.zeros(len(systems)), None, systems)
    bad = sorted(set(iono_coefficients) - {"G", "C"})
    if bad:
        raise SppInputError(f"spp: iono_coefficients: no broadcast model for system(s) {bad}; expected 'G', 'C'")
    if gps_sow is None or np.shape(gps_sow) != (m,):
        raise SppInputError(f"spp: gps_sow: expected ({m},) GPS seconds of week with iono_coefficients, "
                                  f"got {None if gps_sow is None else np.shape(gps_sow)}")
    coef = {k: (np.asarray(a, float), np.asarray(b, float)) for k, (a, b) in iono_coefficients.items()}
    if any(a.shape != (4,) or b.shape != (4,) for a, b in coef.values()):
        raise SppInputError("spp: iono_coefficients: expected {system: (alpha (4,), beta (4,))}")
    freq = C_LIGHT / np.asarray(wavelength_m, float)
    model = np.array([model_system(k) for k in systems])  # Galileo, QZSS, GLONASS: the GPS model from L1
    ref = np.array([reference_frequency(k) if k in coef else np.nan for k in model])
    return _Delays(coef, np.nan_to_num((ref / freq) ** 2), np.asarray(gps_sow, float), model)


def spp(t, code, doppler, wavelength_m, sat_pos_ecef, sat_clock_s, systems, group_delay_m=None,
        elevation_mask_deg=10.0, sigma_code_m=3.0, sigma_doppler_m_per_s=0.1, iterations=10,
        iono_coefficients=None, gps_sow=None, time_offset_s=None, single_clock=False) -> SppFixes:
    """Single-point position and velocity. ``code`` (M, S) m and ``doppler`` (M, S) Hz of one antenna (NaN
    where not tracked; ``doppler`` None: position only, NaN velocity); ``wavelength_m`` (S,) per satellite's signal; ``sat_pos_ecef`` (M, S, 3) m;
    ``sat_clock_s`` (M, S) s; ``systems`` (S,) system letters; ``group_delay_m`` (S,) m;
    ``iono_coefficients`` {'G' or 'C': (alpha (4,), beta (4,))} broadcast Klobuchar coefficients (s, s/semicircle,
    ...; None: no ionospheric correction) with ``gps_sow`` (M,) the epochs' GPS seconds of week.
    ``time_offset_s`` (M, S) s: broadcast system time minus GPS time of each satellite's system (Galileo GGTO, ...),
    added to the satellite clocks so they count GPS time; ``single_clock``: one receiver clock for every system
    (``clock`` (M, 1), ``systems`` one string of the letters) instead of one per system (per-system clocks absorb
    the offsets; one clock needs them removed)."""
    t, code = np.asarray(t, float), np.asarray(code, float)
    m, s = code.shape
    doppler = np.full((m, s), np.nan) if doppler is None else np.asarray(doppler, float)
    if sat_pos_ecef.shape != (m, s, 3) or doppler.shape != (m, s) or sat_clock_s.shape != (m, s):
        raise SppInputError(f"spp: expected code/doppler (M, S), sat_pos_ecef (M, S, 3), sat_clock (M, S) "
                            f"with M={m}, S={s}; got {doppler.shape}, {sat_pos_ecef.shape}, {sat_clock_s.shape}")
    if time_offset_s is not None:
        time_offset_s = np.asarray(time_offset_s, float)
        if time_offset_s.shape != (m, s):
            raise SppInputError(f"spp: expected time_offset_s (M, S) with M={m}, S={s}; got {time_offset_s.shape}")
        sat_clock_s = sat_clock_s + np.nan_to_num(time_offset_s)
    systems = np.asarray(systems)
    names = tuple(sorted(set(systems)))
    onehot = (systems[:, None] == np.array(names)[None, :]).astype(float)
    if single_clock:
        names, onehot = ("".join(names),), np.ones((s, 1))
    gd = np.zeros(s) if group_delay_m is None else np.nan_to_num(np.asarray(group_delay_m, float))
    sat = np.nan_to_num(sat_pos_ecef)
    corrected = code + C_LIGHT * sat_clock_s - gd
    x, e, el, used, ninv, ok = _position(corrected, sat, onehot, np.radians(elevation_mask_deg), sigma_code_m,
                                         iterations, _delays(systems, wavelength_m, iono_coefficients, gps_sow, m))
    n_used = used.sum(1)
    good = _enough(ok, used, onehot)
    x[~good] = np.nan
    vel, vcov = _velocity(t, doppler, wavelength_m, sat_pos_ecef, sat_clock_s, x[:, :3], e, el,
                          used & good[:, None], sigma_doppler_m_per_s)
    lla = ecef_to_lla(x[:, :3])
    rot = ecef_to_enu_matrix(lla[:, 0], lla[:, 1])
    w_pos = np.einsum("mij,mjk,mlk->mil", rot, ninv[:, :3, :3], rot)
    vel_enu = np.einsum("mij,mj->mi", rot, vel)
    v_cov = np.einsum("mij,mjk,mlk->mil", rot, vcov, rot)
    iono = "none" if iono_coefficients is None else \
        "broadcast Klobuchar (" + ", ".join(sorted(iono_coefficients)) + ")"
    return SppFixes(t, x[:, :3], vel_enu, w_pos, v_cov, x[:, 3:], names, np.where(good, n_used, 0), iono)


def _velocity(t, doppler, wavelength, sat, clk, r, e, el, used, sigma):
    m, s = doppler.shape
    if m < 2:
        return np.full((m, 3), np.nan), np.full((m, 3, 3), np.nan)
    vs = np.gradient(sat, t, axis=0, edge_order=2 if m > 2 else 1)
    clk_rate = np.gradient(clk, t, axis=0, edge_order=2 if m > 2 else 1)
    sagnac_rate = OMEGA_E * (vs[..., 0] * r[:, None, 1] - vs[..., 1] * r[:, None, 0]) / C_LIGHT
    y = -np.asarray(wavelength, float)[None, :] * doppler + C_LIGHT * clk_rate - np.einsum("msj,msj->ms", e, vs) \
        - sagnac_rate
    used = used & np.isfinite(y)
    a = np.concatenate([-e, np.ones((m, s, 1))], axis=-1)
    w = np.clip(np.sin(el), 0.1, 1.0) ** 2 / sigma**2
    x, ninv, ok = _solve(a, np.nan_to_num(y), w, used)
    bad = ~ok | (used.sum(1) < 4)
    x[bad] = np.nan
    return x[:, :3], ninv[:, :3, :3]
