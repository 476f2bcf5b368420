"""The filter recursion (numba): strapdown at the IMU rate, covariance propagation every ``cov_dt`` s and before
each update, loosely coupled position/velocity updates at the GNSS epochs, GNSS attitude updates, closed-loop
feedback (the error state is reset to zero after each correction); measurements that fall on sample 0 (the initial
epoch) are applied before the first step. ``mode`` 0 = Kalman, 1 = H-infinity with Wu's
gamma rule, 2 = H-infinity with the weighted gamma rule.

The type of :func:`run`'s ``hinf`` argument, not its value, picks the correction: numba prunes the ``hinf is None``
branch at compile time, so the Kalman loop does not compile the H-infinity correction (its eigenvalue and existence
kernels: a quarter of the loop's cold compile), and each of the two loops is one specialisation.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from . import kalman, model, nav


class Nav(NamedTuple):
    """The navigation state: ``c`` C_b^n (3, 3) body -> ENU, ``v`` (3,) m/s ENU, ``pos`` (3,) [lat rad, lon rad,
    h m], ``bg`` (3,) rad/s gyro and ``ba`` (3,) m/s^2 accelerometer biases, ``lever`` (3,) m body frame, ``gb``
    (3,) m ENU the estimate of the GNSS position fixes' slowly varying error (zero without its states)."""

    c: np.ndarray
    v: np.ndarray
    pos: np.ndarray
    bg: np.ndarray
    ba: np.ndarray
    lever: np.ndarray
    gb: np.ndarray


class Samples(NamedTuple):
    """The compensated IMU (:class:`.increments.Compensated`): ``phi`` (N, 3) rad, ``dvb`` (N, 3) m/s increments
    over ``dt`` (N,) s; ``w_ib`` (N + 1, 3) rad/s body rate at each sample, ``w_mean`` its trailing window mean."""

    phi: np.ndarray
    dvb: np.ndarray
    dt: np.ndarray
    w_ib: np.ndarray
    w_mean: np.ndarray


class Tuning(NamedTuple):
    """``p0`` (n, n) initial covariance, ``qc`` (n,) white-noise densities, ``cov_dt`` s covariance step, ``mode``
    (0 Kalman, 1 H-infinity Wu's gamma, 2 weighted gamma), ``alpha`` the H-infinity alpha; the layout of the
    optional states: ``il`` index of the lever-arm states, ``ib`` of the GNSS position-error states (-1: none),
    ``bias_tau`` s the correlation time of the latter (first-order Gauss-Markov)."""

    p0: np.ndarray
    qc: np.ndarray
    cov_dt: float
    mode: int
    alpha: float
    il: int
    ib: int
    bias_tau: float


class Fixes(NamedTuple):
    """Measurements at IMU samples: ``k`` (M,) sample index, ``z`` (M, q) values, ``r`` (M, q, q) covariance.
    Position/velocity fixes: z = [L rad, lambda rad, h m, vE, vN, vU m/s]; attitude: [pitch, roll, heading] rad."""

    k: np.ndarray
    z: np.ndarray
    r: np.ndarray


class DDRows(NamedTuple):
    """Fixed DD carrier epochs: ``k`` (D,) sample index, ``offsets`` (D + 1,) row offsets, ``los`` (T, 3) ENU
    unit vectors, ``baseline`` (T, 3) m body frame, ``range_m`` (T,) m DD ranges, ``cov_offsets`` (D + 1,),
    ``cov`` the flattened covariance blocks m^2, ``gate`` (D,) NIS gate (inf: off)."""

    k: np.ndarray
    offsets: np.ndarray
    los: np.ndarray
    baseline: np.ndarray
    range_m: np.ndarray
    cov_offsets: np.ndarray
    cov: np.ndarray
    gate: np.ndarray


class Outputs(NamedTuple):
    """The recursion's outputs at the M fix epochs (``c`` .. ``status``, see :func:`allocate`) and the NIS of the
    attitude (K,) and DD (D,) updates."""

    c: np.ndarray
    v: np.ndarray
    pos: np.ndarray
    cov: np.ndarray
    bias: np.ndarray
    lever: np.ndarray
    gamma: np.ndarray
    margin: np.ndarray
    nis: np.ndarray
    w: np.ndarray
    status: np.ndarray
    att_nis: np.ndarray
    dd_nis: np.ndarray
    gnss_error: np.ndarray


@njit(cache=True)
def _feedback(x, st, il, ib):
    """The navigation state ``st`` (:class:`Nav`) corrected by the error state ``x`` (closed loop); ``il``,
    ``ib`` the lever-arm and GNSS-error state indices (-1: none)."""
    lever, gb = st.lever, st.gb
    if il >= 0:
        lever = lever - x[il:il + 3]
    if ib >= 0:
        gb = gb - x[ib:ib + 3]
    return Nav(nav.orthonormalise(nav.rotvec_matrix(x[0:3]) @ st.c), st.v - x[3:6], st.pos - x[6:9],
               st.bg + x[9:12], st.ba + x[12:15], lever, gb)


@njit(cache=True)
def _propagate(p, st, fn, tacc, qc, ib, bias_tau):
    """(P, GNSS-error estimate) after ``tacc`` s from the state ``st`` (:class:`Nav`) at the mean specific force
    ``fn`` (ENU, m/s^2): the GNSS-error states (``ib``; -1 none) are first-order Gauss-Markov with correlation time
    ``bias_tau`` s, and their estimate decays as the error's mean does."""
    f = model.system_matrix(st.c, st.v, st.pos, fn, p.shape[0])
    gb = st.gb
    if ib >= 0:
        for i in range(3):
            f[ib + i, ib + i] = -1.0 / bias_tau
        gb = gb * np.exp(-tacc / bias_tau)
    phim, qd = model.discretise(f, qc, tacc)
    return phim @ p @ phim.T + qd, gb


@njit(cache=True)
def _kalman(p, nu, h, r, alpha, weighted):
    """The Kalman correction of the zero error state, as the H-infinity correction's 7-tuple (x, P, nis, w,
    gamma NaN, margin NaN, status); ``alpha`` and ``weighted`` unused (the H-infinity signature)."""
    x, p, nis, w, status = kalman.correct(np.zeros(p.shape[0]), p, nu, h, r)
    return x, p, nis, w, np.nan, np.nan, status


@njit(cache=True)
def _hinf(p, nu, h, r, alpha, weighted):
    """The H-infinity correction of the zero error state (:func:`.kalman.correct_hinf`)."""
    return kalman.correct_hinf(np.zeros(p.shape[0]), p, nu, h, r, alpha, weighted)


@njit(cache=True)
def _pv_rows(st, w_ib, w_mean, z, n, il, ib):
    """Innovation (INS minus GNSS) and H of a position/velocity fix at the antenna: the prediction from the body
    rate ``w_ib`` at the fix's sample, the lever-arm velocity rows (21 states) from the window mean ``w_mean``.
    Why: the gyro noise n of w_ib is in the innovation as C (n x l); an H row C [(w + n) x] built from the same n
    correlates with it, E[H^T nu] = E[[n x]^T [n x]] l != 0, and the estimate of l is pulled towards zero
    (errors-in-variables regression dilution; with w ~ 0, in straight flight, all the way).
    The fixes' slowly varying error ``st.gb`` (ENU m; states ``ib``) adds to the predicted position: z = p + T_p b.
    ``st`` the navigation state (:class:`Nav`), ``il`` the lever-arm states (-1: none)."""
    c, v, pos, gb = st.c, st.v, st.pos, st.gb
    pred, h = model.antenna_rows(c, v, pos, st.lever, w_ib, n, il)
    if il >= 0:
        h[3:6, il:il + 3] = c @ nav.skew(model.body_rate_nb(c, v, pos, w_mean))
    if ib >= 0:
        tp = model.enu_to_geodetic(pos[0], pos[2])
        pred[0:3] += tp @ gb
        h[0:3, ib:ib + 3] = tp
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
    """Innovation, H and R of the fixed DD carrier rows of DD epoch ``i`` of ``dd`` (:class:`DDRows`; see
    :func:`model.dd_rows`)."""
    a, b = dd.offsets[i], dd.offsets[i + 1]
    m = b - a
    pred, h = model.dd_rows(c, dd.los[a:b], dd.baseline[a:b], n)
    return pred - dd.range_m[a:b], h, dd.cov[dd.cov_offsets[i]:dd.cov_offsets[i + 1]].copy().reshape((m, m))


@njit(cache=True)
def _record(out, j, nav, p, res):
    """Store the state ``nav`` (:class:`Nav`), covariance ``p`` and correction ``res`` of fix ``j`` in ``out``."""
    out.c[j], out.v[j], out.pos[j], out.cov[j] = nav.c, nav.v, nav.pos, p
    out.bias[j, 0:3], out.bias[j, 3:6], out.lever[j], out.gnss_error[j] = nav.bg, nav.ba, nav.lever, nav.gb
    out.nis[j], out.w[j], out.gamma[j], out.margin[j], out.status[j] = res[2], res[3], res[4], res[5], res[6]


def allocate(m, n, k_att, k_dd) -> Outputs:
    """Output arrays at the M GNSS epochs for n states, and the NIS of K attitude and D DD updates (NaN)."""
    return Outputs(np.full((m, 3, 3), np.nan), np.full((m, 3), np.nan), np.full((m, 3), np.nan),
                   np.full((m, n, n), np.nan), np.full((m, 6), np.nan), np.full((m, 3), np.nan), np.full(m, np.nan),
                   np.full(m, np.nan), np.full(m, np.nan), np.full((m, 6), np.nan), np.full(m, -1, dtype=np.int64),
                   np.full(k_att, np.nan), np.full(k_dd, np.nan), np.full((m, 3), np.nan))


@njit(cache=True)
def run(imu, nav0, tuning, gnss, att, dd, out, hinf):
    """The recursion over the compensated IMU ``imu`` (:class:`Samples`; a fix at sample s predicts its lever
    velocity with w_ib[s], H's lever rows use the trailing mean w_mean: :func:`_pv_rows`) from ``nav0``
    (:class:`Nav`) with ``tuning`` (:class:`Tuning`), position/velocity fixes ``gnss`` and attitude fixes ``att``
    (:class:`Fixes`) and the fixed DD carrier ``dd`` (:class:`DDRows`). Fills and returns ``out``
    (:class:`Outputs`). ``hinf``: None (Kalman) or True (H-infinity, ``tuning.mode`` 1 or 2): see the module doc."""
    phi, dvb, dt, w_ib, w_mean = imu
    c, v, pos, bg, ba, lever, gb = nav0
    p, qc, cov_dt, mode, alpha, il, ib, bias_tau = tuning
    gk, gz, gr = gnss
    ak, az, ar = att
    dk = dd.k
    v_prev = v.copy()
    fsum, tacc = np.zeros(3), 0.0
    ig, ia, idd = np.int64(0), np.int64(0), np.int64(0)  # typed int64: a literal 0 would add specialisations
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
            p, gb = _propagate(p, Nav(c, v, pos, bg, ba, lever, gb), fsum / tacc, tacc, qc, ib, bias_tau)
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
                nu, h = _pv_rows(Nav(c, v, pos, bg, ba, lever, gb), w_ib[s] - bg, w_mean[s] - bg, gz[ig], p.shape[0],
                                 il, ib)
                r = gr[ig]
            else:
                continue
            res = _kalman(p, nu, h, r, alpha, False) if hinf is None else _hinf(p, nu, h, r, alpha, mode == 2)
            gated = kind == 1 and not res[2] <= dd.gate[idd]  # DD innovation gate (inf: off): state kept
            if not gated:
                p = res[1]
                c, v, pos, bg, ba, lever, gb = _feedback(res[0], Nav(c, v, pos, bg, ba, lever, gb), il, ib)
            if kind == 0:
                out.att_nis[ia] = res[2]
                ia += 1
            elif kind == 1:
                out.dd_nis[idd] = res[2]
                idd += 1
            else:
                _record(out, ig, Nav(c, v, pos, bg, ba, lever, gb), p, res)
                ig += 1
    return out
