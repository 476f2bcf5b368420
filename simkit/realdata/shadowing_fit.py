"""The street-shadowing channel of :mod:`simkit.gnss.shadowing` estimated from a real drive's C/N0 time series.

Per satellite-epoch above the mask (the default twin's geometry) the real file either tracks the satellite or not
(blocked); a tracked one's C/N0 less its signal's offset, y, is a mixture of a line-of-sight level L_b per
10-degree elevation bin b with a spread s_los, and a shadowed one at L_b - A, A ~ N(mu, s_sh^2) (log-normal
attenuation), the shadowed share w_b per bin. The mixture is fitted by expectation-maximisation (Dempster, Laird
& Rubin 1977): responsibilities g of the shadowed component, then L_b from both components (weighted least
squares), mu, the two spreads and w_b in closed form; 100 iterations from L_b = the bin's 90th percentile. Each
satellite-epoch is then classified (shadowed where g > 1/2) and

* a hidden Markov chain over each satellite's epochs above the mask with these emissions (line of sight and
  shadowed: the mixture's two normals; blocked: not tracked) is smoothed by forward-backward and its one-epoch
  transition matrix A re-estimated (Baum-Welch, started from the counts of the epoch-by-epoch classification,
  :func:`smooth`): the epoch-by-epoch classification flickers where the two components overlap;
* the state probabilities per bin are the mean posterior probabilities of line of sight, shadowed and blocked
  over the satellite-epochs above the mask (a bin with fewer than ``MIN_COUNT`` takes the pooled ones);
* the mean dwell of state i is -dt / ln A_ii (the simulator's step keeps a state with probability about
  exp(-dt / D_i));
* the attenuation's correlation time from the lag-one autocorrelation rho of the attenuation over consecutive
  shadowed epochs, -dt / ln(rho);
* the gain pattern (the line-of-sight C/N0 against elevation) from L_b: the twin's shadowing then takes the
  shadowed epochs' loss off it, where the pattern fitted without the term is the bins' mean over clear and
  shadowed epochs together.

Dwell times are in seconds (the real file's epochs; a drive's speeds from an SPP path are too noisy for metres).
"""
from __future__ import annotations

import numpy as np

from . import fidelity

MIN_COUNT = 30          # satellite-epochs above the mask for a bin's own state probabilities
ITERATIONS = 100
FLOOR_DB = 0.5          # the spreads' floor (a C/N0 quantised to 1 dB or noiseless in a simulated file)


def _bins(el_deg, edges):
    return np.clip(np.searchsorted(edges, el_deg, side="right") - 1, 0, len(edges) - 2)


def _normal(r, mean, sd):
    return np.exp(-0.5 * ((r - mean) / sd) ** 2) / sd


def mixture(y, b, n_bins: int, iterations: int = ITERATIONS) -> dict:
    """EM fit of the two-component model (module docstring) to C/N0 values ``y`` (n,) dB-Hz in bins ``b`` (n,) int:
    {level (B,) (NaN for empty bins), los_sd, mean, sd (attenuation), share (B,), responsibility (n,)}."""
    level = np.full(n_bins, np.nan)
    for k in np.unique(b):
        level[k] = np.quantile(y[b == k], 0.9)
    los_sd, mu, sd = 1.5, 8.0, 4.0
    share = np.full(n_bins, 0.4)
    g = np.zeros(y.size)
    for _ in range(iterations):
        r = y - level[b]
        p_l = (1.0 - share[b]) * _normal(r, 0.0, los_sd)
        p_s = share[b] * _normal(r, -mu, sd)
        g = p_s / np.maximum(p_l + p_s, 1e-300)
        wl, ws = (1.0 - g) / los_sd**2, g / sd**2
        num = np.bincount(b, wl * y + ws * (y + mu), n_bins)
        den = np.bincount(b, wl + ws, n_bins)
        level = np.where(den > 0, num / np.where(den > 0, den, 1.0), np.nan)
        r = y - level[b]
        gs = g.sum()
        mu = float(max(np.sum(g * -r) / gs, 0.0)) if gs > 0 else 0.0
        los_sd = float(max(np.sqrt(np.sum((1.0 - g) * r**2) / max(np.sum(1.0 - g), 1e-9)), FLOOR_DB))
        sd = float(max(np.sqrt(np.sum(g * (r + mu) ** 2) / max(gs, 1e-9)), FLOOR_DB))
        cnt = np.bincount(b, minlength=n_bins)
        share = np.where(cnt > 0, np.bincount(b, g, n_bins) / np.maximum(cnt, 1), 0.4)
        share = np.clip(share, 1e-6, 1.0 - 1e-6)
    return {"level": level, "los_sd": los_sd, "mean": mu, "sd": sd, "share": share, "responsibility": g}


def states(tracked_y, above, shadowed) -> np.ndarray:
    """(M, S) int: 0 line of sight, 1 shadowed, 2 blocked, -1 not above the mask; ``tracked_y`` (M, S) bool where
    the real file has a C/N0, ``above`` (M, S) bool, ``shadowed`` (M, S) bool."""
    out = np.full(above.shape, -1)
    out[above & tracked_y] = 0
    out[above & tracked_y & shadowed] = 1
    out[above & ~tracked_y] = 2
    return out


def smooth(emission, valid, transition, initial, iterations: int = 10):
    """Forward-backward (Baum-Welch: Rabiner, Proc. IEEE 77(2), 1989) over each satellite's runs of ``valid``
    (M, S) epochs: ``emission`` (M, S, 3) the likelihood of each epoch under line of sight, shadowed and blocked,
    ``transition`` (3, 3) one epoch's starting transition matrix, re-estimated ``iterations`` times, ``initial``
    (3,) the state distribution at a run's first epoch. Returns (posterior state probabilities (M, S, 3), the
    transition matrix (3, 3)). A loop over epochs, vectorised over satellites (a fit, not a hot path)."""
    m, n = valid.shape
    start = valid & ~np.vstack([np.zeros((1, n), bool), valid[:-1]])
    cont = valid & ~start
    a = np.asarray(transition, float)
    post = np.zeros((m, n, 3))
    for _ in range(iterations):
        alpha = np.zeros((m, n, 3))
        prev = np.zeros((n, 3))
        for k in range(m):
            f = np.where(start[k][:, None], initial[None, :], prev @ a) * emission[k]
            f = np.where(valid[k][:, None], f, 0.0)
            prev = f / np.maximum(f.sum(axis=1, keepdims=True), 1e-300)
            alpha[k] = prev
        beta = np.ones((m, n, 3))
        xi = np.zeros((3, 3))
        for k in range(m - 2, -1, -1):
            nxt = cont[k + 1]
            eb = emission[k + 1] * beta[k + 1]
            b = eb @ a.T
            b = b / np.maximum(b.sum(axis=1, keepdims=True), 1e-300)
            beta[k] = np.where(nxt[:, None], b, 1.0)
            if nxt.any():
                x = alpha[k][nxt][:, :, None] * a[None] * eb[nxt][:, None, :]
                xi += (x / np.maximum(x.sum(axis=(1, 2), keepdims=True), 1e-300)).sum(axis=0)
        post = alpha * beta
        post = post / np.maximum(post.sum(axis=2, keepdims=True), 1e-300)
        rows = xi.sum(axis=1, keepdims=True)
        a = np.where(rows > 0, xi / np.maximum(rows, 1e-300), a)
    return np.where(valid[..., None], post, 0.0), a


def _channel(y, have, above, b_all, mix, n_bins: int, dt: float):
    """The states (M, S) (:func:`states` codes), state probabilities per bin [(3,)] and dwell times (s) of the
    hidden Markov chain with the mixture ``mix``'s emissions (:func:`smooth`)."""
    shadowed = np.zeros(y.shape, bool)
    shadowed[have] = mix["responsibility"] > 0.5
    st = states(have, above, shadowed)
    # the epoch-by-epoch classification flickers where the two components overlap; the hidden Markov chain with
    # these emissions smooths it, and its transition matrix gives the dwell times
    r = np.where(have, y - mix["level"][b_all], 0.0)
    emission = np.stack([np.where(have, _normal(r, 0.0, mix["los_sd"]), 0.0),
                         np.where(have, _normal(r, -mix["mean"], mix["sd"]), 0.0),
                         np.where(have, 0.0, 1.0)], axis=-1)
    counts = np.array([np.mean(st[above] == s) for s in range(3)])
    start = np.array([[np.sum((st[:-1] == i) & (st[1:] == j)) + 1.0 for j in range(3)] for i in range(3)])
    post, a = smooth(emission, above, start / start.sum(axis=1, keepdims=True), counts)
    st = np.where(above, np.argmax(post, axis=-1), -1)
    probs = shares(post, above, b_all, n_bins)
    # the simulator's step keeps a state with probability about exp(-dt / D)
    dwell = [float(-dt / np.log(min(max(a[i, i], 1e-9), 1.0 - 1e-9))) for i in range(3)]
    return st, probs, dwell, post


def shares(post, where, b_all, n_bins: int) -> list:
    """[(3,)] per bin: the mean posterior state probabilities ``post`` (M, S, 3) over the satellite-epochs ``where``
    (M, S) of the bin; a bin with fewer than ``MIN_COUNT`` takes those pooled over ``where``."""
    pooled = post[where].mean(axis=0)
    out = []
    for k in range(n_bins):
        in_bin = where & (b_all == k)
        out.append(post[in_bin].mean(axis=0) if in_bin.sum() >= MIN_COUNT else pooled)
    return out


def _table(probs) -> dict:
    return {"shadowed_probability": [round(float(p[1]), 4) for p in probs],
            "blocked_probability": [round(float(p[2]), 4) for p in probs]}


def _los_offsets(cn0: dict, offsets: dict, level, los) -> dict:
    """{signal: mean line-of-sight C/N0 less its offset minus the pooled level ``level`` (M, S)} over ``los`` (M, S):
    the offsets fitted to all epochs hold the signals' (systems') different shares of shadowing."""
    shift = {}
    for sig, c in cn0.items():
        r = c - offsets.get(sig, 0.0) - level
        ok = los & np.isfinite(r)
        if ok.sum() >= MIN_COUNT:
            shift[sig] = float(np.mean(r[ok]))
    return shift


def _system_tables(systems, post, above, b_all, n_bins: int) -> dict:
    """{system letter: its own state-probability table} (GLONASS and GPS satellites of one drive need not be
    blocked alike), for the systems of ``systems`` (S,) with ``MIN_COUNT`` satellite-epochs above the mask."""
    out = {}
    for k in sorted(set(systems)) if systems is not None else []:
        where = above & (np.asarray(systems) == k)[None, :]
        if where.sum() >= MIN_COUNT:
            out[k] = _table(shares(post, where, b_all, n_bins))
    return out


def fit(cn0: dict, offsets: dict, el, above, dt: float, edges_deg=fidelity.ELEVATION_EDGES_DEG,
        systems=None) -> dict | None:
    """The channel's parameters from real C/N0 ``cn0`` {signal: (M, S) dB-Hz} (on the twin's grid), each signal's
    C/N0 offset ``offsets`` {signal: dB} (the signal table's plus the fitted one), elevations ``el`` (M, S) rad,
    ``above`` (M, S) bool the satellite-epochs above the mask (the default twin tracks), interval ``dt`` s;
    ``systems`` (S,) the columns' system letters: with two or more systems each gets its own state probabilities
    (``systems`` in the table; the levels, attenuation and dwell times are shared).

    Returns {"config": the ``[gnss.shadowing]`` table, "level_dbhz": L_b per bin (None where empty), "los_sd_db",
    "los_offset_db" {signal: mean line-of-sight C/N0 less its offset, minus L_b}, "state_counts"}; None when the
    file has no C/N0 above the mask."""
    edges = np.asarray(edges_deg, float)
    stack = [c - offsets.get(s, 0.0) for s, c in cn0.items() if np.isfinite(c).any()]
    if not stack:
        return None
    if len(stack) > 1:
        st = np.stack(stack)
        n = np.isfinite(st).sum(axis=0)
        y = np.where(n > 0, np.nansum(st, axis=0) / np.maximum(n, 1), np.nan)
    else:
        y = stack[0]
    el_deg = np.degrees(np.nan_to_num(el, nan=-90.0))
    above = np.asarray(above, bool) & (el_deg >= edges[0])
    have = above & np.isfinite(y)
    if have.sum() < MIN_COUNT:
        return None
    n_bins = edges.size - 1
    b_all = _bins(el_deg, edges)
    mix = mixture(y[have], b_all[have], n_bins)
    st, probs, dwell, post = _channel(y, have, above, b_all, mix, n_bins, dt)
    # attenuation's correlation over consecutive shadowed epochs
    att = np.where(st == 1, mix["level"][b_all] - y, np.nan) - mix["mean"]
    pair = (st[:-1] == 1) & (st[1:] == 1)
    x0, x1 = att[:-1][pair], att[1:][pair]
    rho = float(np.sum(x0 * x1) / np.sqrt(np.sum(x0**2) * np.sum(x1**2))) if pair.sum() >= 10 else None
    corr = float(np.clip(-dt / np.log(rho), dt / 5.0, 3600.0)) if rho is not None and 0.0 < rho < 1.0 else dt
    config = {"elevation_deg": [float(e) for e in edges[:-1]],
              **_table(probs),
              "dwell_s": [round(d, 3) for d in dwell], "attenuation_mean_db": round(mix["mean"], 3),
              "attenuation_sigma_db": round(mix["sd"], 3), "attenuation_correlation_s": round(corr, 3)}
    shift = _los_offsets(cn0, offsets, mix["level"][b_all], st == 0)
    own = _system_tables(systems, post, above, b_all, n_bins)
    if len(own) > 1:
        config["systems"] = own
    counts = np.bincount(b_all[have], minlength=n_bins)
    level = [float(v) if np.isfinite(v) and n >= 10 else None for v, n in zip(mix["level"], counts)]
    return {"config": config, "level_dbhz": level,
            "los_sd_db": mix["los_sd"], "attenuation_lag_one": rho, "los_offset_db": shift,
            "state_counts": [int(np.sum(st == s)) for s in range(3)]}
