"""The filter recursion (numba): strapdown at the IMU rate, covariance propagation every ``cov_dt`` s and before
each update, loosely coupled position/velocity updates at the GNSS epochs, GNSS attitude updates, closed-loop
feedback (the error state is reset to zero after each correction). ``mode`` 0 = Kalman, 1 = H-infinity with Wu's
gamma rule, 2 = H-infinity with the weighted gamma rule."""
from __future__ import annotations

import numpy as np
from numba import njit

from . import kalman, model, nav


@njit(cache=True)
def _feedback(x, c, v, pos, bg, ba, lever):
    c = nav.orthonormalise(nav.rotvec_matrix(x[0:3]) @ c)
    v = v - x[3:6]
    pos = pos - x[6:9]
    bg = bg + x[9:12]
    ba = ba + x[12:15]
    if x.size >= 18:
        lever = lever - x[15:18]
    return c, v, pos, bg, ba, lever


@njit(cache=True)
def _update(p, nu, h, r, mode, alpha):
    x = np.zeros(p.shape[0])
    if mode >= 1:
        return kalman.correct_hinf(x, p, nu, h, r, alpha, mode == 2)
    x, p, nis, w, status = kalman.correct(x, p, nu, h, r)
    return x, p, nis, w, np.nan, np.nan, status


@njit(cache=True)
def _pv_update(p, c, v, pos, lever, w_ib, z, r, mode, alpha):
    pred, h = model.antenna_rows(c, v, pos, lever, w_ib, p.shape[0])
    nu = pred - z
    nu[1] = model.wrap(nu[1])
    return _update(p, nu, h, r, mode, alpha)


@njit(cache=True)
def _att_update(p, c, z, r, mode, alpha):
    e, h = model.attitude_rows(c, p.shape[0])
    nu = e - z
    for i in range(3):
        nu[i] = model.wrap(nu[i])
    return _update(p, nu, h, r, mode, alpha)


@njit(cache=True)
def _dd_update(p, c, dd, i, mode, alpha):
    """Update with the fixed DD carrier rows of DD epoch ``i`` (see :func:`model.dd_rows`), INS minus GNSS."""
    off, los, base, z, roff, cov = dd[1], dd[2], dd[3], dd[4], dd[5], dd[6]
    a, b = off[i], off[i + 1]
    m = b - a
    pred, h = model.dd_rows(c, los[a:b], base[a:b], p.shape[0])
    r = cov[roff[i]:roff[i + 1]].copy().reshape((m, m))
    return _update(p, pred - z[a:b], h, r, mode, alpha)


@njit(cache=True)
def _record(out, j, c, v, pos, p, bg, ba, lever, res):
    o_c, o_v, o_p, o_cov, o_b, o_l, o_g, o_m, o_nis, o_w, o_s = out
    o_c[j], o_v[j], o_p[j], o_cov[j] = c, v, pos, p
    o_b[j, 0:3], o_b[j, 3:6], o_l[j] = bg, ba, lever
    o_nis[j], o_w[j], o_g[j], o_m[j], o_s[j] = res[2], res[3], res[4], res[5], res[6]


def allocate(m, n):
    """Output arrays at the M GNSS epochs for n states."""
    return (np.full((m, 3, 3), np.nan), np.full((m, 3), np.nan), np.full((m, 3), np.nan),
            np.full((m, n, n), np.nan), np.full((m, 6), np.nan), np.full((m, 3), np.nan), np.full(m, np.nan),
            np.full(m, np.nan), np.full(m, np.nan), np.full((m, 6), np.nan), np.full(m, -1, dtype=np.int64))


@njit(cache=True)
def run(phi, dvb, dt, nav0, p, qc, cov_dt, gnss, att, dd, mode, alpha, out, att_nis, dd_nis):
    """The whole recursion. ``nav0`` = (C, v, pos, bg, ba, lever); ``gnss`` = (k (M,) sample index, z (M, 6)
    [L, lambda, h, vE, vN, vU], R (M, 6, 6)); ``att`` = (k (K,), z (K, 3), R (K, 3, 3)); ``dd`` = (k (D,),
    row offsets (D + 1,), G (T, 3), body baselines (T, 3) m, ranges (T,) m, covariance offsets (D + 1,),
    flattened covariance blocks m^2, NIS gate (D,)). Fills ``out``, ``att_nis`` (K,) and ``dd_nis`` (D,)."""
    c, v, pos, bg, ba, lever = nav0
    gk, gz, gr = gnss
    ak, az, ar = att
    dk = dd[0]
    v_prev = v.copy()
    fsum, tacc = np.zeros(3), 0.0
    ig, ia, idd = 0, 0, 0
    for k in range(dt.size):
        s = k + 1
        ph, dv = phi[k] - bg * dt[k], dvb[k] - ba * dt[k]
        c, v_new, pos, fn = nav.step(c, v, pos, v_prev, ph, dv, dt[k])
        v_prev, v = v, v_new
        fsum += fn * dt[k]
        tacc += dt[k]
        g_due = ig < gk.size and gk[ig] == s
        a_due = ia < ak.size and ak[ia] == s
        d_due = idd < dk.size and dk[idd] == s
        if tacc >= cov_dt - 1e-9 or g_due or a_due or d_due:
            phim, qd = model.discretise(model.system_matrix(c, v, pos, fsum / tacc, p.shape[0]), qc, tacc)
            p = phim @ p @ phim.T + qd
            fsum, tacc = np.zeros(3), 0.0
        elif k % 64 == 0:
            c = nav.orthonormalise(c)
        if a_due:
            res = _att_update(p, c, az[ia], ar[ia], mode, alpha)
            p, att_nis[ia] = res[1], res[2]
            c, v, pos, bg, ba, lever = _feedback(res[0], c, v, pos, bg, ba, lever)
            ia += 1
        if d_due:
            res = _dd_update(p, c, dd, idd, mode, alpha)
            dd_nis[idd] = res[2]
            if res[2] <= dd[7][idd]:  # innovation gate (inf: off); a rejected epoch leaves the state alone
                p = res[1]
                c, v, pos, bg, ba, lever = _feedback(res[0], c, v, pos, bg, ba, lever)
            idd += 1
        if g_due:
            res = _pv_update(p, c, v, pos, lever, ph / dt[k], gz[ig], gr[ig], mode, alpha)
            p = res[1]
            c, v, pos, bg, ba, lever = _feedback(res[0], c, v, pos, bg, ba, lever)
            _record(out, ig, c, v, pos, p, bg, ba, lever, res)
            ig += 1
    return out
