"""The INS error model in local-level ENU (Wu 2015 eqs 1-9; Badshah 2015 eqs 36-52 for the lever arm).

Error state (15 or 21), SI units:
    x = [phi_E, phi_N, phi_U (rad), dv_E, dv_N, dv_U (m/s), dL, dlambda (rad), dh (m),
         eps_x, eps_y, eps_z (rad/s, gyro drift, body), nabla_x, nabla_y, nabla_z (m/s^2, accel bias, body),
         (dl_x, dl_y, dl_z (m), lever-arm error, body: 21 states only),
         (db_E, db_N, db_U (m), error of the estimated GNSS position-fix error, ENU: when configured)]
Definitions (computed minus true): C~_b^n = (I - [phi x]) C_b^n, dv = v~ - v, dp = p~ - p, eps and nabla are the
sensor errors left after compensation (measured = true + error), dl = l~ - l. Then (psi-free "phi-angle" form):
    phi'  = -w_in^n x phi + dw_in^n - C_b^n eps
    dv'   = f^n x phi + v x (2 dw_ie^n + dw_en^n) - (2 w_ie^n + w_en^n) x dv + C_b^n nabla + dg^n
    dL'   = dv_N/(R_M+h) - v_N dh/(R_M+h)^2
    dlam' = dv_E sec L/(R_N+h) + v_E sec L tan L dL/(R_N+h) - v_E sec L dh/(R_N+h)^2
    dh'   = dv_U;   eps' = w_g,  nabla' = w_a  (random walks; random constants when their PSD is 0),
    db'   = -db / tau + w_b  (first-order Gauss-Markov: the fixes' error from orbits, clocks and atmosphere),
the equations of Wu 2015 eqs 5-8 with the sign of the drift terms made explicit, plus the gravity-height term
dg_U = 2 gamma / R dh. Discretisation is second order: Phi = I + F T + (F T)^2 / 2, Q_d = (Phi Q_c Phi^T + Q_c) T/2,
with F frozen over the covariance interval T (default 0.1 s).

Measurements (loosely coupled, Badshah 2015 eqs 46-52): antenna position [L, lambda, h] and ENU velocity, INS
minus GNSS, with the lever arm l^b:  p_ant = p + T_p C l (+ T_p b, the fixes' error),   v_ant = v + C (w_nb^b x l),
where T_p maps ENU metres to [dL, dlambda, dh]; and the GNSS attitude [pitch, roll, heading], INS minus GNSS,
with its Jacobian with respect to phi evaluated numerically (the Euler-rate matrix of eq 43).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..earth import OMEGA_E
from .. import frames
from . import nav


@njit(cache=True)
def enu_to_geodetic(lat, h):
    """T_p (3, 3): ENU metres -> [dL, dlambda, dh] (rad, rad, m)."""
    rm, rn = nav.radii(lat)
    t = np.zeros((3, 3))
    t[0, 1] = 1.0 / (rm + h)
    t[1, 0] = 1.0 / ((rn + h) * np.cos(lat))
    t[2, 2] = 1.0
    return t


@njit(cache=True)
def _geo_blocks(lat, h, v):
    """d(dw_ie)/dp, d(dw_en)/dv, d(dw_en)/dp (3x3 each) for p = [L, lambda, h]."""
    rm, rn = nav.radii(lat)
    rm, rn = rm + h, rn + h
    tl, sec2 = np.tan(lat), 1.0 / np.cos(lat) ** 2
    m1 = np.zeros((3, 3))
    m1[1, 0], m1[2, 0] = -OMEGA_E * np.sin(lat), OMEGA_E * np.cos(lat)
    mav = np.zeros((3, 3))
    mav[0, 1], mav[1, 0], mav[2, 0] = -1.0 / rm, 1.0 / rn, tl / rn
    m2 = np.zeros((3, 3))
    m2[0, 2] = v[1] / rm**2
    m2[1, 2] = -v[0] / rn**2
    m2[2, 0], m2[2, 2] = v[0] * sec2 / rn, -v[0] * tl / rn**2
    return m1, mav, m2


@njit(cache=True)
def system_matrix(c, v, pos, fn, n):
    """F (n, n) of the error model at C_b^n ``c``, velocity ``v``, position ``pos`` [L, lambda, h] and specific
    force ``fn`` (ENU, m/s^2)."""
    lat, h = pos[0], pos[2]
    rm, rn = nav.radii(lat)
    rm, rn = rm + h, rn + h
    wie, wen = nav.rates(lat, h, v)
    m1, mav, m2 = _geo_blocks(lat, h, v)
    vx = nav.skew(v)
    f = np.zeros((n, n))
    f[0:3, 0:3] = -nav.skew(wie + wen)
    f[0:3, 3:6] = mav
    f[0:3, 6:9] = m1 + m2
    f[0:3, 9:12] = -c
    f[3:6, 0:3] = nav.skew(fn)
    f[3:6, 3:6] = vx @ mav - nav.skew(2.0 * wie + wen)
    f[3:6, 6:9] = vx @ (2.0 * m1 + m2)
    f[5, 8] += 2.0 * nav.gravity(lat, h) / np.sqrt(rm * rn)
    f[3:6, 12:15] = c
    sec = 1.0 / np.cos(lat)
    f[6, 4], f[6, 8] = 1.0 / rm, -v[1] / rm**2
    f[7, 3], f[7, 6], f[7, 8] = sec / rn, v[0] * sec * np.tan(lat) / rn, -v[0] * sec / rn**2
    f[8, 5] = 1.0
    return f


@njit(cache=True)
def discretise(f, qc, dt):
    """Second-order transition matrix and process noise over ``dt`` s; ``qc`` (n,) continuous PSD diagonal."""
    n = f.shape[0]
    ft = f * dt
    phi = np.eye(n) + ft + 0.5 * (ft @ ft)
    q = np.diag(qc)
    qd = 0.5 * dt * (phi @ q @ phi.T + q)
    return phi, qd


@njit(cache=True)
def euler(c):
    """[pitch, roll, heading] (rad) of C_b^n = R_z(-heading) R_x(pitch) R_y(roll); heading in [0, 2 pi)."""
    pitch = np.arcsin(min(1.0, max(-1.0, c[2, 1])))
    roll = np.arctan2(-c[2, 0], c[2, 2])
    heading = wrap_2pi(np.arctan2(c[0, 1], c[1, 1]))
    return np.array([pitch, roll, heading])


wrap = njit(cache=True)(frames.wrap)  # the compiled form of the one definition, for the filter kernels
wrap_2pi = njit(cache=True)(frames.wrap_2pi)


@njit(cache=True)
def attitude_rows(c, n):
    """(Euler angles of C, H (3, n)): the Jacobian of the Euler angles of (I - [phi x]) C w.r.t. phi."""
    e0 = euler(c)
    h = np.zeros((3, n))
    d = 1e-6
    for j in range(3):
        u = np.zeros(3)
        u[j] = d
        ep = euler((np.eye(3) - nav.skew(u)) @ c)
        em = euler((np.eye(3) + nav.skew(u)) @ c)
        for i in range(3):
            h[i, j] = wrap(ep[i] - em[i]) / (2.0 * d)
    return e0, h


@njit(cache=True)
def body_rate_nb(c, v, pos, w_ib_b):
    """w_nb^b = w_ib^b - C^T (w_ie^n + w_en^n) (rad/s, body) at C_b^n ``c``, ENU ``v``, ``pos`` [L, lambda, h]."""
    wie, wen = nav.rates(pos[0], pos[2], v)
    return w_ib_b - c.T @ (wie + wen)


@njit(cache=True)
def antenna_rows(c, v, pos, lever, w_ib_b, n, il=-1):
    """Predicted antenna [L, lambda, h, v_E, v_N, v_U] and H (6, n) for lever arm ``lever`` (body, m) and body
    rate ``w_ib_b`` (rad/s); ``il`` the index of the lever-arm error states (-1: not estimated)."""
    w_nb = body_rate_nb(c, v, pos, w_ib_b)
    tp = enu_to_geodetic(pos[0], pos[2])
    cl = c @ lever
    cwl = c @ nav.cross(w_nb, lever)
    pred = np.empty(6)
    pred[0:3] = pos + tp @ cl
    pred[3:6] = v + cwl
    h = np.zeros((6, n))
    h[0:3, 0:3] = tp @ nav.skew(cl)
    h[0:3, 6:9] = np.eye(3)
    h[3:6, 0:3] = nav.skew(cwl)
    h[3:6, 3:6] = np.eye(3)
    if il >= 0:
        h[0:3, il:il + 3] = tp @ c
        h[3:6, il:il + 3] = c @ nav.skew(w_nb)
    return pred, h


@njit(cache=True)
def dd_rows(c, los, base_b, n):
    """Predicted fixed DD carrier ranges (m,) m and H (m, n) for DD geometry rows ``los`` (m, 3) (ENU,
    G = -(e_s - e_ref)) and body baselines ``base_b`` (m, 3) m: pred = G . C b^b. With C~ = (I - [phi x]) C,
    d pred / d phi = G [(C b) x] = s_b^T [b x] C^T for s_b = C^T G: Wang 2018 eq 16 (body-frame DD line of
    sight and baseline) turned into the ENU attitude error of this filter."""
    m = los.shape[0]
    pred = np.empty(m)
    h = np.zeros((m, n))
    for i in range(m):
        bn = c @ base_b[i]
        pred[i] = los[i] @ bn
        h[i, 0:3] = los[i] @ nav.skew(bn)
    return pred, h
