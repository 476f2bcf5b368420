"""Two-ray multipath: the tracking errors of a direct signal plus one specular reflection.

The reflection arrives ``delta`` chips (its extra path over the chip length) after the direct signal, with
amplitude ratio ``alpha`` (< 1) and relative carrier phase ``theta`` = 2 pi extra / lambda + pi (the extra path
plus the reflection's half-cycle). The PLL locks to the composite carrier, so the carrier error is

    psi = atan2(alpha sin theta, 1 + alpha cos theta)              [rad], |psi| <= asin(alpha)

and the coherent early-late DLL (spacing D chips, ideal triangular correlation R(x) = max(0, 1 - |x|), infinite
bandwidth) settles where the in-phase discriminator

    R(e - D/2) - R(e + D/2) + beta [R(e - delta - D/2) - R(e - delta + D/2)] = 0,
    beta = alpha cos(theta - psi) / cos(psi) = alpha (cos theta + alpha) / (1 + alpha cos theta),

vanishes with a positive slope; the discriminator is piecewise linear, so the zero nearest the direct peak is
found exactly between its breakpoints. The classic envelopes follow (Braasch, in Parkinson & Spilker 1996, ch.
14): in phase e = alpha delta / (1 + alpha) for delta < (1 + alpha) D / 2 and alpha D / 2 beyond, out of phase
-alpha delta / (1 - alpha) then -alpha D / 2; the error vanishes for delta > 1 + D / 2 and |e| <= alpha D / 2.
"""
from __future__ import annotations

import numpy as np


def carrier_phase_error(alpha, theta):
    """Composite carrier phase error psi (rad) of a reflection of amplitude ratio ``alpha`` at relative phase
    ``theta`` (rad)."""
    return np.arctan2(alpha * np.sin(theta), 1.0 + alpha * np.cos(theta))


def carrier_phase_error_rate(alpha, theta, theta_rate):
    """d psi / dt (rad/s) for a relative phase changing at ``theta_rate`` rad/s."""
    return alpha * (alpha + np.cos(theta)) / (1.0 + 2.0 * alpha * np.cos(theta) + alpha**2) * theta_rate


def amplitude_gain_db(alpha, theta):
    """Composite amplitude over the direct one, dB (20 log10 |1 + alpha e^(i theta)|)."""
    return 10.0 * np.log10(1.0 + 2.0 * alpha * np.cos(theta) + alpha**2)


def _tri(x):
    return np.maximum(0.0, 1.0 - np.abs(x))


def dll_error_chips(alpha, delta, theta, spacing):
    """Code tracking error (chips, positive: late) of a coherent early-late DLL of early-late spacing ``spacing``
    chips for a reflection ``delta`` chips late, amplitude ratio ``alpha`` and relative phase ``theta`` rad.
    Arrays broadcast together."""
    alpha, delta, theta = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (alpha, delta, theta)))
    beta = alpha * (np.cos(theta) + alpha) / (1.0 + alpha * np.cos(theta))
    h = 0.5 * spacing
    shifts = np.array([h, -h])
    ks = np.array([-1.0, 0.0, 1.0])
    base = np.concatenate([(shifts[:, None] + ks[None]).ravel()] * 2)            # 12 breakpoints
    bp = np.sort(base + np.concatenate([np.zeros(6), np.ones(6)]) * delta[..., None], axis=-1)
    b = beta[..., None]
    d = delta[..., None]
    f = _tri(bp - h) - _tri(bp + h) + b * (_tri(bp - d - h) - _tri(bp - d + h))
    f0, f1, x0, x1 = f[..., :-1], f[..., 1:], bp[..., :-1], bp[..., 1:]
    up = (f0 < 0.0) & (f1 >= 0.0) & (x1 > x0)
    with np.errstate(divide="ignore", invalid="ignore"):
        root = np.where(up, x0 - f0 * (x1 - x0) / (f1 - f0), np.inf)
    pick = np.argmin(np.abs(root), axis=-1)
    return np.take_along_axis(root, pick[..., None], axis=-1)[..., 0]
