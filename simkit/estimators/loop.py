"""The filter recursion (numba): strapdown at the IMU rate, covariance propagation every ``cov_dt`` s and before
each update, loosely coupled position/velocity updates at the GNSS epochs, GNSS attitude updates, closed-loop
feedback (the error state is reset to zero after each correction); measurements that fall on sample 0 (the initial
epoch) are applied before the first step. ``mode`` 0 = Kalman, 1 = H-infinity with Wu's
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
def _kalman(p, nu, h, r):
    """The Kalman correction of the zero error state, as the H-infinity correction's 7-tuple (x, P, nis, w,
    gamma NaN, margin NaN, status)."""
    x, p, nis, w, status = kalman.correct(np.zeros(p.shape[0]), p, nu, h, r)
    return x, p, nis, w, np.nan, np.nan, status


@njit(cache=True)
def _pv_rows(c, v, pos, lever, w_ib, w_mean, z, n):
    """Innovation (INS minus GNSS) and H of a position/velocity fix at the antenna: the prediction from the body
    rate ``w_ib`` at the fix's sample, the lever-arm velocity rows (21 states) from the window mean ``w_mean``.
    Why: the gyro noise n of w_ib is in the innovation as C (n x l); an H row C [(w + n) x] built from the same n
    correlates with it, E[H^T nu] = E[[n x]^T [n x]] l != 0, and the estimate of l is pulled towards zero
    (errors-in-variables regression dilution; with w ~ 0, in straight flight, all the way)."""
    pred, h = model.antenna_rows(c, v, pos, lever, w_ib, n)
    if n >= 18:
        h[3:6, 15:18] = c @ nav.skew(model.body_rate_nb(c, v, pos, w_mean))
    nu = pred - z
    nu[1] = model.wrap(nu[1])
    return nu, h


@njit(cache=True)
def _att_rows(c, z, n):
    """Innovation (INS minus GNSS, wrapped) and H of a GNSS attitude fix [pitch, roll, heading]."""
    e, h = model.attitude_rows(c, n)
    nu = e - z
    for i in range(3):
        nu[i] = model.wrap(nu[i])
    return nu, h


@njit(cache=True)
def _dd_rows(c, dd, i, n):
    """Innovation, H and R of the fixed DD carrier rows of DD epoch ``i`` (see :func:`model.dd_rows`)."""
    off, los, base, z, roff, cov = dd[1], dd[2], dd[3], dd[4], dd[5], dd[6]
    a, b = off[i], off[i + 1]
    m = b - a
    pred, h = model.dd_rows(c, los[a:b], base[a:b], n)
    return pred - z[a:b], h, cov[roff[i]:roff[i + 1]].copy().reshape((m, m))


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
def run(phi, dvb, dt, w_ib, w_mean, nav0, p, qc, cov_dt, gnss, att, dd, mode, alpha, out, att_nis, dd_nis):
    """The recursion over the compensated increments ``phi``, ``dvb``, ``dt`` and the body rate ``w_ib`` (N, 3)
    rad/s at each sample (:class:`.increments.Compensated`; a fix at sample s predicts its lever velocity with
    w_ib[s], H's lever rows use the trailing mean ``w_mean`` (N, 3): :func:`_pv_rows`). ``nav0`` = (C, v, pos,
    bg, ba, lever); ``gnss`` = (k (M,) sample index, z (M, 6) [L, lambda, h, vE, vN, vU], R (M, 6, 6)); ``att`` =
    (k (K,), z (K, 3), R (K, 3, 3)); ``dd`` = (k (D,), row offsets (D + 1,), G (T, 3), body baselines (T, 3) m,
    ranges (T,) m, covariance offsets, covariance blocks m^2, NIS gate (D,)). Fills out, att_nis (K,), dd_nis (D,)."""
    c, v, pos, bg, ba, lever = nav0
    gk, gz, gr = gnss
    ak, az, ar = att
    dk = dd[0]
    v_prev = v.copy()
    fsum, tacc = np.zeros(3), 0.0
    ig, ia, idd = 0, 0, 0
    for s in range(dt.size + 1):  # sample s; interval k = s - 1 leads to it (sample 0: the initial epoch)
        k = max(s - 1, 0)
        ph = phi[k] - bg * dt[k]
        if s > 0:
            c, v_new, pos, fn = nav.step(c, v, pos, v_prev, ph, dvb[k] - ba * dt[k], dt[k])
            v_prev, v = v, v_new
            fsum += fn * dt[k]
            tacc += dt[k]
        g_due = ig < gk.size and gk[ig] == s
        a_due = ia < ak.size and ak[ia] == s
        d_due = idd < dk.size and dk[idd] == s
        if tacc > 0.0 and (tacc >= cov_dt - 1e-9 or g_due or a_due or d_due):
            phim, qd = model.discretise(model.system_matrix(c, v, pos, fsum / tacc, p.shape[0]), qc, tacc)
            p = phim @ p @ phim.T + qd
            fsum, tacc = np.zeros(3), 0.0
        elif k % 64 == 0:
            c = nav.orthonormalise(c)
        # the updates of this sample, in order: GNSS attitude, fixed DD carrier, position/velocity. One call
        # site per correction, in the loop itself: numba/LLVM optimise the corrections into the loop once
        for kind in range(3):
            if kind == 0 and a_due:
                nu, h = _att_rows(c, az[ia], p.shape[0])
                r = ar[ia]
            elif kind == 1 and d_due:
                nu, h, r = _dd_rows(c, dd, idd, p.shape[0])
            elif kind == 2 and g_due:
                nu, h = _pv_rows(c, v, pos, lever, w_ib[s] - bg, w_mean[s] - bg, gz[ig], p.shape[0])
                r = gr[ig]
            else:
                continue
            res = kalman.correct_hinf(np.zeros(p.shape[0]), p, nu, h, r, alpha, mode == 2) if mode >= 1 else \
                _kalman(p, nu, h, r)
            gated = kind == 1 and not res[2] <= dd[7][idd]  # DD innovation gate (inf: off): state left alone
            if not gated:
                p = res[1]
                c, v, pos, bg, ba, lever = _feedback(res[0], c, v, pos, bg, ba, lever)
            if kind == 0:
                att_nis[ia] = res[2]
                ia += 1
            elif kind == 1:
                dd_nis[idd] = res[2]
                idd += 1
            else:
                _record(out, ig, c, v, pos, p, bg, ba, lever, res)
                ig += 1
    return out
