"""Code noise and C/N0 of a real receiver against its twin, per elevation bin, with the sampling uncertainty of
each bin's figure, and the smooth code-noise model the calibrated twin is fitted to.

Every function takes plain arrays of one antenna: series (M, S) (epochs x satellites, NaN where absent),
elevations (M, S) rad.

* **Uncertainty of a bin's sigma.** The sample standard deviation of n Gaussian values has a relative standard
  error of about 1/sqrt(2 n). Multipath is correlated in time, so consecutive epochs of a satellite are not
  independent: for a first-order autoregressive series with lag-one autocorrelation rho, a variance estimate is
  worth n_eff = n (1 - rho^2) / (1 + rho^2) independent values (the squares of a Gaussian AR(1) series have
  autocorrelation rho^(2k); Bartlett 1946), a mean n (1 - rho) / (1 + rho) (Wilks, Statistical Methods in the
  Atmospheric Sciences, eq. 5.12; used for the C/N0 means). rho is pooled over the pairs of consecutive epochs
  of the same satellite inside the bin.
* **Equal-count bins.** A fixed 10-degree grid leaves bins with a handful of values whose sigma is uncertain by
  tens of percent: no comparison can resolve 20 % there. :func:`equal_count_edges` splits the real file's
  elevations of a signal at quantiles into as many bins as keep n_eff >= ``n_eff_min`` in each (at most
  ``max_bins``); the edges depend on the elevations only, never on the values compared.
* **The twin's expectation.** The twin's sigma in a bin is one draw too; the twin side is taken over several
  realisations (seeds): its values pooled, its n_eff the sum, so its scatter does not dominate the comparison.
* **Smooth code model.** A free factor per elevation bin overfits the sampling scatter of a short file and
  transfers badly to other epochs. :func:`smooth_correction` fits, per signal, log(twin / real) = a + b (el -
  45 deg) / 45 deg by weighted least squares (weights 1 / standard error^2, a ridge towards zero slope) and
  returns the code-factor table of ``[gnss.code_error_scale]`` that removes it: two parameters per signal.
"""
from __future__ import annotations

import numpy as np
from scipy.stats import norm

TOLERANCE = 0.2          # the code-noise target: twin sigma within 20 % of the real one
N_EFF_MIN = 50.0         # effective values per equal-count bin: a sigma to about 1/sqrt(100) = 10 %


def lag_one(x) -> float | None:
    """Pooled lag-one autocorrelation of ``x`` (M, S) over pairs of consecutive finite values of a column
    (the series are zero-mean per arc); None without a pair."""
    x = np.asarray(x, float)
    a, b = x[:-1], x[1:]
    ok = np.isfinite(a) & np.isfinite(b)
    den = float(np.sum(a[ok] ** 2) + np.sum(b[ok] ** 2)) / 2.0
    return float(np.sum(a[ok] * b[ok]) / den) if den > 0 else None


def n_effective(n: int, rho, of: str = "mean") -> float:
    """The number of independent values worth ``n`` values of an AR(1) series with lag-one autocorrelation
    ``rho`` (n otherwise; at least 1): for its mean n (1 - rho) / (1 + rho); for its variance (``of="variance"``)
    n (1 - rho^2) / (1 + rho^2), the autocorrelation of the squares being rho^2 at lag one (Bartlett 1946)."""
    if rho is None or not np.isfinite(rho) or rho <= 0 or n < 1:
        return float(max(n, 1))
    r = min(rho, 0.99) ** (2 if of == "variance" else 1)
    return float(max(1.0, n * (1.0 - r) / (1.0 + r)))


def _in_bin(values, el_deg, lo, hi):
    inside = (el_deg >= lo) & (el_deg < hi) & np.isfinite(values)
    return np.where(inside, values, np.nan)


def _column_jackknife(x, stat: str) -> float | None:
    """Standard error of the mean (``stat="mean"``) or standard deviation ("std") of the finite values of
    ``x`` (M, S) by the delete-one-column jackknife (Efron & Stein 1981); None with fewer than three columns."""
    ok = np.isfinite(x)
    cols = ok.any(axis=0)
    x0 = np.where(ok, x, 0.0)[:, cols]
    n_i, s1_i, s2_i = ok[:, cols].sum(0), x0.sum(0), (x0 ** 2).sum(0)
    m = n_i.sum() - n_i
    keep = m >= 2
    if keep.sum() < 3:
        return None
    mean = (s1_i.sum() - s1_i[keep]) / m[keep]
    theta = mean if stat == "mean" else np.sqrt(np.maximum((s2_i.sum() - s2_i[keep]) / m[keep] - mean ** 2, 0.0))
    k = theta.size
    return float(np.sqrt((k - 1) / k * np.sum((theta - theta.mean()) ** 2)))


def jackknife_rel_se(x) -> float | None:
    """Relative standard error of the standard deviation of the finite values of ``x`` (M, S) by the delete-one-
    satellite (column) jackknife: the satellite is the sampling unit, so the spread between satellites'
    multipath (one reflector geometry each at a static station) counts, which n_eff of a common series cannot
    see; None with fewer than three satellites."""
    se = _column_jackknife(x, "std")
    v = x[np.isfinite(x)]
    return float(se / np.std(v)) if se is not None and v.size and np.std(v) > 0 else None


def bin_sigma(values, el_deg, lo: float, hi: float) -> dict:
    """{n, rho, n_eff, sigma, rel_se, rel_se_satellites} of ``values`` (M, S) whose elevation (deg) is in
    [lo, hi): sigma the standard deviation; rel_se = 1 / sqrt(2 n_eff) its relative standard error as a common
    AR(1) series; rel_se_satellites the jackknife over satellites (:func:`jackknife_rel_se`)."""
    x = _in_bin(values, el_deg, lo, hi)
    v = x[np.isfinite(x)]
    if v.size < 3:
        return {"n": int(v.size), "rho": None, "n_eff": float(v.size), "sigma": None, "rel_se": None,
                "rel_se_satellites": None}
    rho = lag_one(x - np.nanmean(v))
    ne = n_effective(v.size, rho, "variance")
    return {"n": int(v.size), "rho": rho, "n_eff": ne, "sigma": float(np.std(v)), "rel_se": float(1 / np.sqrt(2 * ne)),
            "rel_se_satellites": jackknife_rel_se(x)}


def bin_mean(values, el_deg, lo: float, hi: float) -> dict:
    """{n, satellites, n_eff, mean, se} of ``values`` (M, S) in the elevation bin [lo, hi) deg: se the larger of
    std / sqrt(n_eff) and the jackknife over satellites (a bin's mean C/N0 is mostly which satellites, clear or
    shadowed, happen to be in it)."""
    x = _in_bin(values, el_deg, lo, hi)
    v = x[np.isfinite(x)]
    sats = int(np.isfinite(x).any(axis=0).sum())
    if v.size < 3:
        return {"n": int(v.size), "satellites": sats, "n_eff": float(v.size), "mean": None, "se": None}
    ne = n_effective(v.size, lag_one(x - v.mean()))
    se = max(float(np.std(v) / np.sqrt(ne)), _column_jackknife(x, "mean") or 0.0)
    return {"n": int(v.size), "satellites": sats, "n_eff": ne, "mean": float(v.mean()), "se": se}


def equal_count_edges(values, el_deg, floor_deg: float, n_eff_min: float = N_EFF_MIN, max_bins: int = 6) -> list:
    """Elevation bin edges (deg) for ``values`` (M, S): quantiles of the elevations of its finite values, as
    many bins as keep about ``n_eff_min`` effective values each (the series' pooled lag-one autocorrelation), at
    least one and at most ``max_bins``; the outer edges ``floor_deg`` and 90."""
    ok = np.isfinite(values) & np.isfinite(el_deg) & (el_deg >= floor_deg)
    e = np.sort(el_deg[ok])
    if e.size == 0:
        return [float(floor_deg), 90.0]
    ne = n_effective(e.size, lag_one(np.where(ok, values, np.nan)), "variance")
    k = int(np.clip(np.floor(ne / n_eff_min), 1, max_bins))
    inner = np.quantile(e, np.arange(1, k) / k) if k > 1 else np.array([])
    inner = np.unique(np.round(inner, 2))
    return [float(floor_deg), *(float(x) for x in inner), 90.0]


def code_comparison(real_mp: dict, twin_mps: list, el, floor_deg: float, edges: dict | None = None,
                    n_eff_min: float = N_EFF_MIN, max_bins: int = 6) -> dict:
    """Per signal: the code-noise sigma of the real file and of the twin (pooled over the realisations of
    ``twin_mps``) in equal-count elevation bins, over the satellite-epochs both have a value, with their
    uncertainties, the ratio twin / real and its relative standard error sqrt(rel_se_real^2 + rel_se_twin^2),
    the real side's the larger of its n_eff and its jackknife-over-satellites figure (the twin draws every
    satellite's multipath from one model: its realisations pooled, n_eff is its figure).

    ``real_mp`` {signal: (M, S)}, ``twin_mps`` [{signal: (M, S)}] on the same grid (one per seed), ``el`` (M, S)
    rad; ``edges`` {signal: edges} to use given edges (else :func:`equal_count_edges` on the real values)."""
    el_deg = np.degrees(el)
    out = {}
    for s, r in real_mp.items():
        twins = [t[s] for t in twin_mps if s in t]
        if not twins:
            continue
        both = [np.isfinite(r) & np.isfinite(t) for t in twins]
        common = np.any(both, axis=0)
        rr = np.where(common, r, np.nan)
        e = (edges or {}).get(s) or equal_count_edges(rr, el_deg, floor_deg, n_eff_min, max_bins)
        pooled_t = np.concatenate([np.where(b, t, np.nan) for b, t in zip(both, twins)], axis=1)
        pooled_el = np.tile(el_deg, (1, len(twins)))
        rows = []
        for lo, hi in zip(e[:-1], e[1:]):
            a, b = bin_sigma(rr, el_deg, lo, hi), bin_sigma(pooled_t, pooled_el, lo, hi)
            ratio = se = None
            real_se = max(a["rel_se"] or 0.0, a["rel_se_satellites"] or 0.0)
            if a["sigma"] and b["sigma"] is not None:
                ratio = b["sigma"] / a["sigma"]
                se = float(np.hypot(real_se, b["rel_se"]))
            rows.append({"bin_deg": [float(lo), float(hi)], "real_m": a["sigma"], "real_n": a["n"],
                         "real_n_eff": a["n_eff"], "real_rel_se_series": a["rel_se"],
                         "real_rel_se_satellites": a["rel_se_satellites"], "real_rel_se": real_se or None,
                         "twin_m": b["sigma"], "twin_n_eff": b["n_eff"], "twin_rel_se": b["rel_se"], "ratio": ratio,
                         "ratio_rel_se": se})
        out[s] = {"edges_deg": [float(x) for x in e], "bins": rows}
    return {"signals": out, "twin_realisations": len(twin_mps), "summary": code_summary(out)}


def code_summary(per_signal: dict, tol: float = TOLERANCE) -> dict:
    """Bins with a ratio; within ``tol``, and how many a twin equal to the receiver in expectation would have
    within ``tol`` given the bins' standard errors; resolved (ratio standard error <= tol / 2, so a 20 % mismatch is
    two standard errors); mismatched beyond two standard errors; median ratio; and the chi-square of
    log(ratio) against its standard errors per degree of freedom (1 = the bins agree up to sampling)."""
    rows = [b for v in per_signal.values() for b in v["bins"] if b["ratio"]]
    if not rows:
        return {"bins": 0}
    ratio = np.array([b["ratio"] for b in rows])
    se = np.array([b["ratio_rel_se"] for b in rows])
    z = np.log(ratio) / se
    # a twin equal to the receiver in expectation: log(ratio) ~ N(0, se), within tol with this probability
    p_within = norm.cdf(np.log(1 + tol) / se) - norm.cdf(np.log(1 - tol) / se)
    return {"bins": len(rows), "within": int(np.sum(np.abs(ratio - 1) <= tol)),
            "expected_within_if_equal": float(np.sum(p_within)),
            "resolved": int(np.sum(se <= tol / 2)),
            "within_of_resolved": int(np.sum((np.abs(ratio - 1) <= tol) & (se <= tol / 2))),
            "beyond_two_se": int(np.sum(np.abs(z) > 2)), "median_ratio": float(np.median(ratio)),
            "chi2_per_bin": float(np.mean(z ** 2)), "median_ratio_rel_se": float(np.median(se))}


def satellite_spread(values, el_deg, edges_deg) -> float | None:
    """Standard deviation (the values' unit) of the satellites' means about their elevation bin's mean, pooled
    over the bins that hold two or more satellites: the spread a bin's mean has from which satellites are in
    it (their power, and at a street their shadowing), whatever its number of epochs; None without such a bin."""
    num = dof = 0.0
    for lo, hi in zip(edges_deg[:-1], edges_deg[1:]):
        x = _in_bin(values, el_deg, lo, hi)
        n = np.isfinite(x).sum(0)
        m = np.nansum(x, 0)[n > 0] / n[n > 0]
        if m.size >= 2:
            num += float(np.sum((m - m.mean()) ** 2))
            dof += m.size - 1
    return float(np.sqrt(num / dof)) if dof else None


# Output steps of receivers' reported C/N0 (dB-Hz), coarsest first: whole dB-Hz (many mass-market receivers),
# halves, quarters (RINEX 3 files of geodetic receivers), fifths, eighths, tenths
CN0_STEPS_DBHZ = (1.0, 0.5, 0.25, 0.2, 0.125, 0.1)


def cn0_resolution(series) -> float:
    """The step of a receiver's reported C/N0 (dB-Hz): the coarsest of :data:`CN0_STEPS_DBHZ` of which every
    value in ``series`` (arrays, NaN where absent) is a multiple, to the 0.001 dB-Hz that RINEX writes; 0 when
    there is none (a continuous estimate) or fewer than 10 values or 3 distinct ones (nothing to tell)."""
    values = np.concatenate([np.ravel(np.asarray(x, float)) for x in series] or [np.empty(0)])
    values = values[np.isfinite(values)]
    if values.size < 10 or np.unique(values).size < 3:
        return 0.0
    for step in CN0_STEPS_DBHZ:
        if np.all(np.abs(values - step * np.round(values / step)) < 5e-4):
            return step
    return 0.0


def cn0_comparison(real_cn0: dict, twin_cn0s: list, el, edges_deg) -> dict:
    """Per signal: mean C/N0 (dB-Hz) of real and twin (pooled over realisations) per elevation bin over the
    satellite-epochs both track, with standard errors (:func:`bin_mean`; the real side's at least the
    :func:`satellite_spread` over sqrt(satellites in the bin)), and the difference twin - real split
    into its bias (mean over bins), scatter (std over bins) and RMS; ``rms_se_dbhz`` the RMS of the differences'
    standard errors (the RMS that sampling alone would give) and ``chi2_per_bin`` the mean squared difference in
    standard errors (about 1 when the bins differ by sampling only); per bin the standard deviation of the C/N0
    values (real, twin pooled: the spread street shadowing gives) and ``spread_rms_db`` the RMS over the bins of
    twin - real of it."""
    el_deg = np.degrees(el)
    out = {}
    for s, r in real_cn0.items():
        twins = [t[s] for t in twin_cn0s if s in t]
        if not twins or not np.isfinite(r).any():
            continue
        both = [np.isfinite(r) & np.isfinite(t) for t in twins]
        rr = np.where(np.any(both, axis=0), r, np.nan)
        pooled = np.concatenate([np.where(b, t, np.nan) for b, t in zip(both, twins)], axis=1)
        pel = np.tile(el_deg, (1, len(twins)))
        rows, diffs, ses, spread = [], [], [], []
        between = satellite_spread(rr, el_deg, edges_deg)
        for lo, hi in zip(edges_deg[:-1], edges_deg[1:]):
            a, b = bin_mean(rr, el_deg, lo, hi), bin_mean(pooled, pel, lo, hi)
            if a["se"] is not None and between is not None:     # a bin of one or two satellites
                a["se"] = max(a["se"], between / np.sqrt(a["satellites"]))
            d = b["mean"] - a["mean"] if a["mean"] is not None and b["mean"] is not None and a["n"] >= 10 else None
            if d is not None:
                diffs.append(d)
            se = float(np.hypot(a["se"], b["se"])) if d is not None else None
            if d is not None:
                ses.append(se)
            sd_r = sd_t = None
            if d is not None:      # the spread of the values within the bin, real and twin
                sd_r = float(np.nanstd(_in_bin(rr, el_deg, lo, hi)))
                sd_t = float(np.nanstd(_in_bin(pooled, pel, lo, hi)))
                spread.append(sd_t - sd_r)
            rows.append({"bin_deg": [float(lo), float(hi)], "real_dbhz": a["mean"], "real_n": a["n"],
                         "real_satellites": a["satellites"], "real_se": a["se"], "twin_dbhz": b["mean"],
                         "twin_se": b["se"], "difference": d, "difference_se": se, "real_sd_db": sd_r,
                         "twin_sd_db": sd_t})
        out[s] = {"bins": rows, **_differences(diffs, ses),
                  "spread_rms_db": float(np.sqrt(np.mean(np.square(spread)))) if spread else None}
    return out


def _differences(diffs: list, ses: list) -> dict:
    """Bias (mean), scatter (std) and RMS of the per-bin differences ``diffs`` (dB-Hz), the RMS of their standard
    errors ``ses`` and the mean squared difference in standard errors (chi-square per bin); None each when empty."""
    d, e = np.array(diffs), np.array(ses)
    if not d.size:
        return dict.fromkeys(("bias_dbhz", "scatter_dbhz", "rms_dbhz", "rms_se_dbhz", "chi2_per_bin"))
    return {"bias_dbhz": float(d.mean()), "scatter_dbhz": float(d.std()), "rms_dbhz": float(np.sqrt(np.mean(d ** 2))),
            "rms_se_dbhz": float(np.sqrt(np.mean(e ** 2))),
            "chi2_per_bin": float(np.mean((d / e) ** 2)) if (e > 0).all() else None}


def cn0_drift(bins: list, other_cn0, el_other) -> dict:
    """The real file's C/N0 against itself: each compared bin of :func:`cn0_comparison` (``bins``, the checked
    epochs) gets the real mean over the *other* epochs (``other_cn0`` (M', S) dB-Hz, elevations ``el_other`` rad,
    e.g. the epochs a split fitted on; :func:`bin_mean`), and the differences checked - other over the bins are
    summarised as the twin's are (bias, scatter, RMS, the RMS of their standard errors, chi-square per bin): the
    RMS a perfect model of the receiver could not beat on these epochs, the environment having changed."""
    el_deg = np.degrees(el_other)
    between = satellite_spread(other_cn0, el_deg, [b["bin_deg"][0] for b in bins] + [bins[-1]["bin_deg"][1]]) \
        if bins else None
    diffs, ses = [], []
    for b in bins:
        if b["difference"] is None:
            continue
        o = bin_mean(other_cn0, el_deg, *b["bin_deg"])
        if o["se"] is not None and between is not None:
            o["se"] = max(o["se"], between / np.sqrt(o["satellites"]))
        b["real_other_dbhz"] = o["mean"]
        if o["mean"] is None or o["n"] < 10:
            continue
        diffs.append(b["real_dbhz"] - o["mean"])
        ses.append(float(np.hypot(b["real_se"], o["se"])))
    if not diffs:
        return {"bins": 0}
    return {"bins": len(diffs), **_differences(diffs, ses)}


def drift(per_signal: dict, other_mp: dict, el_other, tol: float = TOLERANCE) -> dict:
    """The real file against itself: each bin of :func:`code_comparison`'s ``per_signal`` (the checked epochs)
    gets the real sigma over the *other* epochs (``other_mp`` {signal: (M', S)}, elevations ``el_other`` rad,
    e.g. the epochs a split fitted on) in the same edges and their ratio ``real_drift`` = checked / other. A
    model of the receiver alone (one sigma per elevation) cannot follow a drift the environment makes; the
    summary counts the bins whose real drift is within ``tol`` and beyond two standard errors."""
    el_deg = np.degrees(el_other)
    ratios, ses = [], []
    for s, v in per_signal.items():
        if s not in other_mp:
            continue
        for b in v["bins"]:
            o = bin_sigma(other_mp[s], el_deg, *b["bin_deg"])
            b["real_other_m"] = o["sigma"]
            b["real_drift"] = b["real_m"] / o["sigma"] if o["sigma"] and b["real_m"] else None
            if b["real_drift"]:
                ratios.append(b["real_drift"])
                ses.append(np.hypot(b["real_rel_se"] or 0.0, max(o["rel_se"] or 0.0, o["rel_se_satellites"] or 0.0)))
    r, e = np.array(ratios), np.array(ses)
    if not r.size:
        return {"bins": 0}
    return {"bins": int(r.size), "within": int(np.sum(np.abs(r - 1) <= tol)),
            "beyond_two_se": int(np.sum(np.abs(np.log(r)) > 2 * e)), "median_drift": float(np.median(r))}


def smooth_correction(per_signal: dict, current: dict, nodes_deg=tuple(range(0, 91, 10)),
                      slope_prior: float = 0.5) -> dict:
    """{signal: (elevation nodes deg, code factors)}: each signal's factor of ``current`` ({signal: number or
    table}, the parameters of the twin that produced ``per_signal``, :func:`code_comparison`'s ``signals``)
    divided by exp(a + b x), x = (el - 45) / 45, the weighted least-squares line through log(ratio) of its bins
    (weights 1/rel_se^2) with a zero-mean prior of standard deviation ``slope_prior`` on b, so that one bin, or
    bins too uncertain to show a trend, give a level only.
    Code noise and code multipath are both linear in the factor, so the correction moves the twin's expected
    sigma onto the real one's smooth trend, not onto each bin's sampling scatter."""
    from ..gnss.config import angle_table_at

    out = {}
    nodes = np.asarray(nodes_deg, float)
    for s, v in per_signal.items():
        rows = [b for b in v["bins"] if b["ratio"]]
        if not rows:
            continue
        x = np.array([(0.5 * sum(b["bin_deg"]) - 45.0) / 45.0 for b in rows])
        y = np.log([b["ratio"] for b in rows])
        w = 1.0 / np.square([b["ratio_rel_se"] for b in rows])
        a_mat = np.stack([np.ones_like(x), x], axis=1) * np.sqrt(w)[:, None]
        lhs = a_mat.T @ a_mat + np.diag([0.0, slope_prior ** -2])
        a, b = np.linalg.solve(lhs, a_mat.T @ (y * np.sqrt(w)))
        now = np.broadcast_to(angle_table_at(current.get(s, 1.0), np.radians(nodes)), nodes.shape)
        out[s] = (tuple(float(n) for n in nodes), tuple(float(f) for f in now / np.exp(a + b * (nodes - 45) / 45)))
    return out
