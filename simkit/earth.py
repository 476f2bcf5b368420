"""WGS-84 Earth model: constants, radii of curvature, normal gravity, Earth and transport rates.

Every physical constant simkit uses is defined here once (the ellipsoid, Earth rate, normal gravity, standard
gravity G0, the speed of light); ``ELLIPSOID`` hands the same ellipsoid to pymap3d.

All angles in radians, heights in metres above the ellipsoid, vectors in the local-level ENU frame (n).
Gravity follows NIMA TR8350.2: closed-form Somigliana (eq. 4-1) times the height series of eq. 4-3; it
contains the centrifugal part and acts along minus the ellipsoid normal. Truth and estimators both use it.
"""
from __future__ import annotations

import numpy as np

A = 6378137.0                      # semi-major axis, m
F = 1.0 / 298.257223563            # flattening
B = A * (1.0 - F)                  # semi-minor axis, m
E2 = F * (2.0 - F)                 # first eccentricity squared
OMEGA_E = 7.292115e-5              # WGS-84 Earth rotation rate, rad/s
GM = 3.986004418e14                # m^3/s^2
GAMMA_E = 9.7803253359             # normal gravity at the equator, m/s^2
K_SOMIGLIANA = 0.00193185265241    # (b*gamma_p)/(a*gamma_e) - 1
M_RATIO = OMEGA_E**2 * A**2 * B / GM  # 0.00344978650684
C_LIGHT = 299792458.0              # m/s
EARTH_RATE_ECEF = np.array([0.0, 0.0, OMEGA_E])  # w_ie^e, rad/s
G0 = 9.80665                       # standard gravity, m/s^2: the unit behind "g", "mg", "ug" and load factors


def __getattr__(name):
    """``ELLIPSOID``: the same a and b as a pymap3d ``Ellipsoid``, for pymap3d's geodesy (made on first use:
    importing pymap3d costs a truth + IMU run ~10 ms of start-up it never needs)."""
    if name == "ELLIPSOID":
        import pymap3d

        globals()["ELLIPSOID"] = pymap3d.Ellipsoid(A, B, name="WGS-84", model="wgs84")
        return globals()["ELLIPSOID"]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def radii(lat, sin_lat=None):
    """Meridian (R_M) and prime-vertical (R_N) radii of curvature at geodetic latitude ``lat`` (rad), m.
    ``sin_lat``: sin(lat) when the caller has it (here and below: the same numbers, one sine fewer)."""
    s2 = (np.sin(lat) if sin_lat is None else sin_lat) ** 2
    w = np.sqrt(1.0 - E2 * s2)
    rn = A / w
    rm = A * (1.0 - E2) / (w * w * w)  # not w**3: numpy's pow costs 6x two products (the truth calls this 8x a block)
    return rm, rn


def normal_gravity(lat, h, sin_lat=None):
    """Magnitude of WGS-84 normal gravity (m/s^2) at geodetic latitude ``lat`` (rad) and height ``h`` (m)."""
    s2 = (np.sin(lat) if sin_lat is None else sin_lat) ** 2
    g0 = GAMMA_E * (1.0 + K_SOMIGLIANA * s2) / np.sqrt(1.0 - E2 * s2)
    return g0 * (1.0 - 2.0 / A * (1.0 + F + M_RATIO - 2.0 * F * s2) * h + 3.0 * h**2 / A**2)


def gravity_enu(lat, h, sin_lat=None):
    """Normal gravity vector in ENU, (..., 3) m/s^2: [0, 0, -gamma(lat, h)]."""
    g = np.asarray(normal_gravity(lat, h, sin_lat), dtype=float)
    out = np.zeros(g.shape + (3,))
    out[..., 2] = -g
    return out


def earth_rate_enu(lat, sin_lat=None, cos_lat=None):
    """Earth rotation rate w_ie^n in ENU, (..., 3) rad/s."""
    lat = np.asarray(lat, dtype=float)
    out = np.zeros(lat.shape + (3,))
    out[..., 1] = OMEGA_E * (np.cos(lat) if cos_lat is None else cos_lat)
    out[..., 2] = OMEGA_E * (np.sin(lat) if sin_lat is None else sin_lat)
    return out


def transport_rate(lat, h, v_east, v_north, sin_lat=None):
    """Transport rate w_en^n by component: its E, N and U arrays (rad/s) for the east and north velocity (m/s,
    relative to Earth); the truth's form, contiguous arrays rather than an (N, 3) one."""
    rm, rn = radii(lat, sin_lat)
    return -v_north / (rm + h), v_east / (rn + h), v_east * np.tan(lat) / (rn + h)


def transport_rate_enu(lat, h, vel_enu, sin_lat=None):
    """Transport rate w_en^n in ENU, (..., 3) rad/s, for velocity ``vel_enu`` (m/s, relative to Earth)."""
    v = np.asarray(vel_enu, dtype=float)
    return np.stack(transport_rate(lat, h, v[..., 0], v[..., 1], sin_lat), axis=-1)
