"""The truth ionosphere: the broadcast Klobuchar delay times a correlated random factor, or a global ionosphere map.

The receiver corrects its code with the broadcast Klobuchar model, which removes roughly half of the ionospheric
delay (RMS). The truth therefore departs from it:

* without a map: I_true = k I_Klobuchar exp(s e(x, t) - s^2/2), k the mean ratio (``iono_scale``, 1 by default:
  at night or at solar minimum the real ionosphere can sit well below the model's floor), where e is a zero-mean,
  unit-variance Gaussian-like random field of the ionospheric pierce point x (on a 350 km shell, Earth-fixed,
  km) and time t, with covariance exp(-|dx|^2 / (2 L^2) - dt^2 / (2 tau^2)), built as a sum of 64 random Fourier
  features (Rahimi and Recht 2007); s = sqrt(ln(1 + f^2)) so that RMS(I_true / (k I_Klobuchar) - 1) = f
  (``iono_residual_fraction``). The random factor is positive (no negative delays) and its mean is 1. The field
  is a smooth function of position and time, so the delay rate is consistent with the delay and the output does
  not depend on how epochs are split into blocks.
* with an IONEX map: I_true = 40.3 VTEC(x, t) / f^2 on the map's shell with the single-layer mapping 1/cos z'.

Rates are central differences over +-``h`` s along the receiver's and the satellites' motion, as in
:func:`simkit.gnss.atmosphere.ionosphere`.
"""
from __future__ import annotations

import numpy as np

from .. import earth, rng
from .atmosphere import broadcast_ionosphere, reference_frequency
from .feature_sum import feature_sums
from .iono_steps import klobuchar_and_pierce_points
from .ionex import IONO_CONSTANT, TECU, IonexMaps, slant_factor

SHELL_HEIGHT_M = 350e3            # thin-shell height of the random field's pierce points
SHELL_RADIUS_M = 6378.1363e3      # Earth radius of the thin shell (as RTKLIB's ionppp)
N_FEATURES = 64


def pierce_point(lat, lon, az, el, radius_m: float = SHELL_RADIUS_M, height_m: float = SHELL_HEIGHT_M):
    """Latitude and longitude (rad) of the pierce point on a spherical shell ``height_m`` above a sphere of
    ``radius_m`` for a receiver at ``lat``/``lon`` rad seeing a satellite at ``az``/``el`` rad (RTKLIB ionppp's
    geometry, including its branch for lines of sight over a pole)."""
    rp = radius_m / (radius_m + height_m) * np.cos(el)
    psi = np.pi / 2.0 - el - np.arcsin(rp)
    sinap = np.sin(lat) * np.cos(psi) + np.cos(lat) * np.sin(psi) * np.cos(az)
    lat_p = np.arcsin(sinap)
    tanap = np.tan(psi)
    over_pole = ((lat > np.radians(70.0)) & (tanap * np.cos(az) > np.tan(np.pi / 2.0 - lat))) | \
                ((lat < -np.radians(70.0)) & (-tanap * np.cos(az) > np.tan(np.pi / 2.0 + lat)))
    d = np.arcsin(np.clip(np.sin(psi) * np.sin(az) / np.cos(lat_p), -1.0, 1.0))
    lon_p = np.where(over_pole, lon + np.pi - d, lon + d)
    return lat_p, lon_p


class ResidualField:
    """Zero-mean, unit-variance random field e(x, t) with a Gaussian covariance of length ``length_m`` and time
    ``time_s``; its random features come from the stream ``gnss/truth/ionosphere`` of ``seed``."""

    def __init__(self, seed: int, length_m: float, time_s: float, n_features: int = N_FEATURES):
        gen = rng.generator(seed, "gnss", "truth", "ionosphere")
        self.k = gen.standard_normal((n_features, 3)) / length_m
        self.w = gen.standard_normal(n_features) / time_s
        self.phase = gen.uniform(0.0, 2.0 * np.pi, n_features)
        self.scale = np.sqrt(2.0 / n_features)

    def __call__(self, x, t, chunk: int = 1 << 15):
        """e at Earth-fixed points ``x`` (..., 3) m and times ``t`` (...) s (broadcast together); evaluated
        ``chunk`` points at a time so that memory stays bounded (chunk x features)."""
        x, t = np.broadcast_arrays(x, np.asarray(t, dtype=float)[..., None])
        shape = x.shape[:-1]
        xs, ts = x.reshape(-1, 3), t[..., 0].reshape(-1)
        out = np.empty(xs.shape[0])
        for i in range(0, xs.shape[0], chunk):
            arg = xs[i:i + chunk] @ self.k.T + ts[i:i + chunk, None] * self.w + self.phase
            out[i:i + chunk] = np.cos(arg).sum(axis=-1)
        return self.scale * out.reshape(shape)

    def clusters(self, x, t, dt):
        """e at points ``x`` (M, A, J, C, 3) m close to (m, 0, J // 2, c) (antennas and time steps of one satellite,
        metres apart) at times ``t`` (M,) + ``dt`` (J,) s: :func:`simkit.gnss.feature_sum.feature_sums`, equal to
        :meth:`__call__` within 1e-13."""
        return self.scale * feature_sums(self.k, self.w, self.phase, x, t, dt)


class TruthIonosphere:
    """Truth ionospheric delay at a system's reference frequency (L1 for GPS, B1I for BDS): ``scale`` times
    Klobuchar with ``fraction`` the RMS relative departure about it (scale 1, fraction 0: the truth is Klobuchar),
    or ``ionex`` maps (which then replace both)."""

    def __init__(self, seed: int, fraction: float, length_m: float, time_s: float, ionex: IonexMaps | None = None,
                 scale: float = 1.0):
        self.ionex = ionex
        self.scale = float(scale)
        self.sigma = float(np.sqrt(np.log1p(fraction**2)))
        self.field = ResidualField(seed, length_m, time_s) if self.sigma > 0 and ionex is None else None

    @property
    def departs(self) -> bool:
        return self.field is not None or self.ionex is not None or self.scale != 1.0

    def delay(self, system, alpha, beta, lla, vel_enu, az, el, az_rate, el_rate, week, sow, t, h: float = 0.05):
        """(truth, truth rate, Klobuchar) in m and m/s for receivers at ``lla`` (M, A, 3) moving at ``vel_enu``
        (M, A, 3) m/s, satellites at ``az``/``el`` (M, A, C) rad with rates in rad/s, GPS ``week``/``sow`` and
        ``t`` s since the start, each (M, 1, 1) (one time per epoch)."""
        lat, lon, hgt = lla[..., 0, None], lla[..., 1, None], lla[..., 2, None]
        rm, rn = earth.radii(lat)
        lat_rate = vel_enu[..., 1, None] / (rm + hgt)
        lon_rate = vel_enu[..., 0, None] / ((rn + hgt) * np.cos(lat))
        steps = (-h, 0.0, h)
        if self.field is not None and self.ionex is None:
            return self._field_delay(system, alpha, beta, lat[..., 0], lon[..., 0], lat_rate[..., 0],
                                     lon_rate[..., 0], az, el, az_rate, el_rate, sow, t, steps)
        klob, points = [], []
        for s in steps:
            la, lo, a, e = lat + s * lat_rate, lon + s * lon_rate, az + s * az_rate, el + s * el_rate
            klob.append(broadcast_ionosphere(system, alpha, beta, la, lo, a, e, sow + s))
            if self.ionex is not None:
                m = self.ionex
                lat_p, lon_p = pierce_point(la, lo, a, e, m.base_radius_m, m.height_m)
                tec = m.vtec(week, sow + s, lat_p, lon_p) * slant_factor(e, m.base_radius_m, m.height_m)
                points.append(IONO_CONSTANT * TECU * tec / reference_frequency(system) ** 2)
        truth = points if self.ionex is not None else [self.scale * k for k in klob]
        return truth[1], (truth[2] - truth[0]) / (2.0 * h), klob[1]

    def _field_delay(self, system, alpha, beta, lat, lon, lat_rate, lon_rate, az, el, az_rate, el_rate, sow, t,
                     steps):
        """:meth:`delay` with the random field: Klobuchar and pierce points in one compiled pass
        (:mod:`simkit.gnss.iono_steps`), receivers (M, A), lines of sight (M, A, C)."""
        shape = np.broadcast_shapes(np.shape(az), np.shape(el))
        az, el = np.broadcast_to(az, shape), np.broadcast_to(el, shape)
        az_rate, el_rate = np.broadcast_to(az_rate, shape), np.broadcast_to(el_rate, shape)
        lat, lon, lat_rate, lon_rate = (np.broadcast_to(x, shape[:2]) for x in (lat, lon, lat_rate, lon_rate))
        epoch_sow = np.broadcast_to(np.asarray(sow, dtype=float), shape)[:, 0, 0]
        epoch_t = np.broadcast_to(np.asarray(t, dtype=float), shape)[:, 0, 0]
        klob, points = klobuchar_and_pierce_points(system, alpha, beta, lat, lon, lat_rate, lon_rate, az, el,
                                                   az_rate, el_rate, epoch_sow, np.array(steps), SHELL_RADIUS_M,
                                                   SHELL_HEIGHT_M)
        e = self.field.clusters(points, epoch_t, np.array(steps))                          # (M, A, 3, C)
        truth = klob * (self.scale * np.exp(self.sigma * e - 0.5 * self.sigma**2))
        return truth[:, :, 1], (truth[:, :, 2] - truth[:, :, 0]) / (2.0 * steps[2]), klob[:, :, 1]
