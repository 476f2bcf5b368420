"""What a drive's out-of-sample C/N0 mismatch is made of, and which C/N0-against-elevation form transfers best
(docs/real_data.md, "C/N0 out of sample on Berlin").

On a real file with signal strengths and the receiver's path (a simkit file with an SPP solution):

1. the C/N0 residual about the least-squares model zenith + signal offset - rolloff ((90 - el) / 90)^2 split into
   the spread between satellites (their mean residuals) and within a satellite over time (shadowing along the
   route); the change of each satellite's mean residual between the fitted and the checked epochs of the two
   splits of ``simkit twin`` (half, interleaved);
2. each elevation form fitted on one part and checked on the other, as the twin compares them (mean per 10-degree
   bin over the real satellite-epochs, RMS over the bins): a constant, a sin(el) line, the simulator's quadratic
   rolloff, a quadratic in sin(el), a step per bin (what ``--fit`` writes as the gain pattern), and the steps
   shrunk towards the quadratic by their standard errors.

The model's C/N0 is noiseless in the simulator, so its bin means over the real satellite-epochs are what the
twin's are on the satellite-epochs both track.

Run: python benchmarks/twin_cn0_models.py OBS NAV SPP_H5 [--solution spp]
"""
import argparse
import json

import numpy as np

from simkit.gnss import signals as sigmod
from simkit.logs import read
from simkit.realdata import fidelity, importer, noise_fit, twin

EDGES = fidelity.ELEVATION_EDGES_DEG
FORMS = ("constant", "sin", "quadratic", "sin_quadratic", "step", "step_shrunk")


def _design(el, form):
    if form == "constant":
        return np.empty((el.size, 0))
    if form == "sin":
        return np.sin(el)[:, None]
    if form == "sin_quadratic":
        return np.column_stack([np.sin(el), np.sin(el) ** 2])
    return -(((np.pi / 2 - el) / (np.pi / 2)) ** 2)[:, None]          # quadratic (and the steps' offsets)


def fit_form(cn0, el, sigs, rows, form):
    """Coefficients [level, offsets of signals 2.., shape...] of ``form`` by least squares on the epochs ``rows``."""
    xs, ys = [], []
    for k, s in enumerate(sigs):
        ok = rows[:, None] & np.isfinite(cn0[s]) & np.isfinite(el)
        e = el[ok]
        off = np.zeros((e.size, len(sigs) - 1))
        if k:
            off[:, k - 1] = 1.0
        xs.append(np.column_stack([np.ones(e.size), off, _design(e, "quadratic" if form.startswith("step") else form)]))
        ys.append(cn0[s][ok])
    return np.linalg.lstsq(np.vstack(xs), np.concatenate(ys), rcond=None)[0]


def predict(beta, el, k, form, nsig, steps=None):
    off = beta[k] if k else 0.0
    if steps is not None:
        idx = np.clip(np.floor(np.nan_to_num(np.degrees(el)) / 10).astype(int), 0, len(steps) - 1)
        return np.asarray(steps)[idx] + off
    shape = _design(el.ravel(), form) @ beta[nsig:]
    return beta[0] + off + shape.reshape(el.shape)


def step_levels(cn0, el, sigs, rows, beta, shrink):
    """Per-bin levels of the signals' C/N0 less their fitted offsets (the gain-pattern steps), optionally shrunk
    towards the quadratic by their standard errors (:func:`noise_fit.bin_mean`)."""
    pooled = np.concatenate([np.where(rows[:, None], cn0[s] - (beta[k] if k else 0.0), np.nan)
                             for k, s in enumerate(sigs)], axis=1)
    pel = np.tile(np.degrees(el), (1, len(sigs)))
    quad = predict(beta, np.radians(0.5 * (EDGES[:-1] + EDGES[1:])), 0, "quadratic", len(sigs))
    st = [noise_fit.bin_mean(pooled, pel, lo, hi) for lo, hi in zip(EDGES[:-1], EDGES[1:])]
    lev = np.array([b["mean"] if b["mean"] is not None and b["n"] >= 10 else np.nan for b in st])
    se = np.array([b["se"] if b["se"] is not None else np.nan for b in st])
    if shrink:
        ok = np.isfinite(lev)
        tau2 = max(np.mean((lev - quad)[ok] ** 2) - np.mean(se[ok] ** 2), 0.0)
        lev = quad + tau2 / (tau2 + se ** 2) * (lev - quad)
    return np.where(np.isfinite(lev), lev, quad)


def bin_means(x, el, rows):
    d = np.degrees(el)
    out = []
    for lo, hi in zip(EDGES[:-1], EDGES[1:]):
        m = rows[:, None] & (d >= lo) & (d < hi) & np.isfinite(x)
        out.append(float(x[m].mean()) if m.sum() >= 10 else np.nan)
    return np.array(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("obs")
    ap.add_argument("nav")
    ap.add_argument("trajectory")
    ap.add_argument("--solution", default="spp")
    args = ap.parse_args()
    real = twin.real_arrays(importer.import_rinex(args.obs, [args.nav], None, None))
    ref = np.nanmedian(read(args.trajectory, solution=args.solution).pos_ecef, axis=0)
    el = fidelity.elevations(real["sat_pos"], ref)
    sigs = [s for s in real["signals"] if np.isfinite(real["obs"]["cn0"][s]).any()]
    cn0 = {s: real["obs"]["cn0"][s] for s in sigs}
    t = real["t"]
    splits = {k: twin.split_rows(t, k) for k in twin.SPLITS}
    everything = np.ones(t.size, bool)
    beta = fit_form(cn0, el, sigs, everything, "quadratic")
    out = {"signals": sigs, "systems": [sigmod.get(s).system for s in sigs], "decomposition": {}, "forms": {}}
    for k, s in enumerate(sigs):
        r = cn0[s] - predict(beta, el, k, "quadratic", len(sigs))
        cols = np.isfinite(r).any(axis=0)
        r = r[:, cols]
        n = np.isfinite(r).sum(0)
        means = np.nansum(r, 0) / n
        total = float(np.nanvar(r))
        between = float(np.average((means - np.nanmean(r)) ** 2, weights=n))
        q90 = np.nanpercentile(r, 90, axis=0)
        dec = {"residual_sd_db": float(np.sqrt(total)), "between_satellites_db2": between,
               "within_satellites_db2": total - between,
               "share_6db_below_own_p90": float(np.sum(r < q90 - 6) / np.isfinite(r).sum())}
        for name, rows in splits.items():
            a = np.nanmean(np.where(rows[:, None], r, np.nan), 0)
            b = np.nanmean(np.where(~rows[:, None], r, np.nan), 0)
            ok = np.isfinite(a) & np.isfinite(b)
            dec[f"{name}_satellite_mean_change_rms_db"] = float(np.sqrt(np.mean((a - b)[ok] ** 2)))
        out["decomposition"][s] = dec
    for name, rows in splits.items():
        check = ~rows
        res = {}
        for form in FORMS:
            b = fit_form(cn0, el, sigs, rows, form)
            steps = step_levels(cn0, el, sigs, rows, b, form == "step_shrunk") if form.startswith("step") else None
            res[form] = {}
            for k, s in enumerate(sigs):
                p = predict(b, el, k, form, len(sigs), steps)
                d = bin_means(np.where(np.isfinite(cn0[s]), p, np.nan), el, check) - bin_means(cn0[s], el, check)
                d = d[np.isfinite(d)]
                res[form][s] = {"bias_db": round(float(d.mean()), 2), "scatter_db": round(float(d.std()), 2),
                                "rms_db": round(float(np.sqrt(np.mean(d ** 2))), 2)}
        out["forms"][name] = res
    print(json.dumps(out, indent=1))


with np.errstate(invalid="ignore", divide="ignore"):
    if __name__ == "__main__":
        main()
