"""The real ionosphere against the broadcast Klobuchar model, from a receiver's dual-frequency code and carrier.

Per system with a Klobuchar model (GPS, BDS) the first two signals of the file on different frequencies f1 > f2
(gamma = (f1/f2)^2) give the geometry-free combinations, in metres:

    P2 - P1 - (gd2 - gd1)   = (gamma - 1) I1 + B        (code: the satellites' group delays of the navigation data
    L1 - L2                 = (gamma - 1) I1 + N        removed, B the receiver's inter-frequency bias)

The carrier one is levelled to the code over each continuous arc (N = the arc mean of their difference; arcs as
in :func:`.fidelity.arcs`), which keeps the carrier's precision and the code's level. I1 = levelled / (gamma - 1)
is then fitted as B/(gamma - 1) + k K per system by least squares, K the Klobuchar delay on f1 of the same
satellite-epoch: the receiver bias is a constant of the system, k the mean ratio of the real ionosphere to the
model. The residual fraction compared with simkit's truth model (``iono_residual_fraction``, the RMS of
I_true / I_Klobuchar - 1, docs/truth_errors.md) is the RMS over satellites of their arc-mean ratio
(I1 - B/(gamma - 1)) / K - 1, the mean bias (k - 1) included.

Limits: the broadcast group delays are good to a few tenths of a nanosecond (some decimetres on I1 at most), and
a receiver bias that is not common to all satellites of a system (GLONASS FDMA) would need another model; a
short file sees one sample of the ionosphere's residual field.
"""
from __future__ import annotations

import numpy as np

from .. import gpstime
from ..constellation.geometry import angles_from_enu, lines_of_sight_enu
from ..earth import C_LIGHT
from ..gnss import atmosphere
from ..gnss import signals as sigmod
from . import fidelity

MIN_SATELLITES = 4


def klobuchar_ratio(real: dict, reference, group_delay, iono: dict) -> dict:
    """{system: {signals, satellites, epochs, receiver_bias_m, mean_ratio, residual_fraction, ratio_per_satellite}}
    for the GPS and BDS pairs of ``real`` (the dict of :func:`.twin.real_arrays`), the receiver at ``reference``
    (3,) m ECEF, ``group_delay`` (S, G) m per satellite and signal (/gnss/group_delay), ``iono`` {system: (alpha, beta)}; a system
    without a pair, a model or ``MIN_SATELLITES`` satellites is left out."""
    import pymap3d

    signals, freq, t = real["signals"], np.asarray(real["freq"]), real["t"]
    rx = np.broadcast_to(np.asarray(reference, float), (t.size, 3))
    with np.errstate(invalid="ignore"):
        el, az = angles_from_enu(lines_of_sight_enu(rx, real["sat_pos"])[0])
    lat, lon, _ = pymap3d.ecef2geodetic(*np.asarray(reference, float), deg=False)
    week, sow = gpstime.add_seconds(*real["start"], t)
    sys_of_sat = np.array([s[0] for s in real["sat_id"]])
    out = {}
    for system in ("G", "C"):
        pair = dual_frequency_pair(signals, freq, system)
        if pair is None or system not in iono:
            continue
        i, j = pair
        cols = sys_of_sat == system
        gamma = (freq[i] / freq[j]) ** 2
        obs = real["obs"]
        p_gf = (obs["code"][signals[j]] - group_delay[None, :, j]) - (obs["code"][signals[i]] - group_delay[None, :, i])
        l_gf = obs["carrier"][signals[i]] * C_LIGHT / freq[i] - obs["carrier"][signals[j]] * C_LIGHT / freq[j]
        lli = obs["lli"][signals[i]].astype(np.uint8) | obs["lli"][signals[j]].astype(np.uint8)
        valid = np.isfinite(p_gf) & np.isfinite(l_gf) & np.isfinite(el) & cols[None, :]
        label = fidelity.arcs(valid, lli, t, np.where(valid, l_gf, np.nan))
        levelled = level_to_carrier(l_gf, p_gf - l_gf, label)
        alpha, beta = iono[system]
        klob = atmosphere.broadcast_ionosphere(system, np.asarray(alpha), np.asarray(beta), lat, lon, az,
                                               np.where(np.isfinite(el), el, np.pi / 2), sow[:, None])
        klob = klob * (atmosphere.reference_frequency(system) / freq[i]) ** 2
        ok = np.isfinite(levelled) & (el > 0)
        if len(np.unique(np.nonzero(ok)[1])) < MIN_SATELLITES:
            continue
        y, k_model = levelled[ok] / (gamma - 1.0), klob[ok]
        (bias, k), *_ = np.linalg.lstsq(np.column_stack([np.ones(y.size), k_model]), y, rcond=None)
        ratio = np.full(levelled.shape, np.nan)
        ratio[ok] = (y - bias) / k_model
        per_sat = {real["sat_id"][s]: float(np.nanmean(ratio[:, s])) for s in np.unique(np.nonzero(ok)[1])}
        dev = np.array(list(per_sat.values())) - 1.0
        out[system] = {"signals": [signals[i], signals[j]], "satellites": len(per_sat), "epochs": int(ok.sum()),
                       "receiver_bias_m": float(bias * (gamma - 1.0)), "mean_ratio": float(k),
                       "residual_fraction": float(np.sqrt(np.mean(dev ** 2))),
                       "ratio_per_satellite": per_sat}
    return out


def residual_fraction(result: dict) -> float | None:
    """One fraction for the truth model: the per-system fractions weighted by their satellite counts."""
    if not result:
        return None
    w = np.array([r["satellites"] for r in result.values()], float)
    f = np.array([r["residual_fraction"] for r in result.values()])
    return float(np.sqrt(np.sum(w * f ** 2) / np.sum(w)))


def dual_frequency_pair(signals, freq, system):
    """Indices (higher, lower frequency) of the system's first two signals on different frequencies."""
    idx = [k for k, s in enumerate(signals) if sigmod.get(s).system == system]
    for k in idx[1:]:
        if freq[k] != freq[idx[0]]:
            return (idx[0], k) if freq[idx[0]] > freq[k] else (k, idx[0])
    return None


def level_to_carrier(l_gf, diff, label):
    """``l_gf`` plus the mean of ``diff`` over each arc of ``label`` (NaN outside arcs)."""
    out = np.full(l_gf.shape, np.nan)
    ok = label >= 0
    ids, inv = np.unique(label[ok], return_inverse=True)
    mean = np.bincount(inv, weights=diff[ok]) / np.bincount(inv)
    out[ok] = l_gf[ok] + mean[inv]
    return out
