"""Ray tests against vertical walls (numba): direct blocking and single specular reflections (image method).

Rays start at an antenna (east, north, up in metres in the origin's local plane) towards a satellite at azimuth
``az`` (clockwise from north) and elevation ``el``; a satellite is at infinity, so its rays are parallel. A ray
is blocked by a wall when it crosses the wall's segment below the wall's top. The walls a ray may meet are found
by walking the grid's cells along its horizontal trace (Amanatides and Woo), up to where the ray has risen above
the highest wall.

Reflection off the face of wall w that the antenna sees (unit normal n towards the antenna, distance d): the
satellite lights that face when n.u > 0 (u the unit vector to the satellite); the reflected ray reaches the
antenna from the mirror direction u' = u - 2 (n.u) n, which meets the wall after s = d / (n.u) metres at Q; the
path is longer than the direct one by 2 d (n.u) = 2 d cos(el) cos(az - az_n). The reflection counts when Q lies on
the wall (within the segment, below the top, within ``range_m`` horizontally of the antenna) and both legs
(antenna -> Q and Q -> satellite) are clear of the other walls. Of the valid reflections the one with the
shortest extra path is kept.
"""
from __future__ import annotations

import math

import numba
import numpy as np

_EPS_T = 1e-9      # m: a ray does not hit the wall it starts on
_INF = np.inf


@numba.njit(cache=True, nogil=True)
def _hits(ox, oy, oz, dx, dy, tan_el, t_max, exclude, w0, w1, ax, ay, bx, by, top, cell_walls):
    """Whether the ray hits one of the walls cell_walls[w0:w1] within horizontal distance t_max."""
    for k in range(w0, w1):
        w = cell_walls[k]
        if w == exclude:
            continue
        ex, ey = bx[w] - ax[w], by[w] - ay[w]
        den = dx * ey - dy * ex
        if den == 0.0:
            continue
        px, py = ax[w] - ox, ay[w] - oy
        t = (px * ey - py * ex) / den
        if t <= _EPS_T or t > t_max:
            continue
        lam = (px * dy - py * dx) / den
        if lam < 0.0 or lam > 1.0:
            continue
        if oz + t * tan_el < top[w]:
            return True
    return False


@numba.njit(cache=True, nogil=True)
def blocked(ox, oy, oz, dx, dy, tan_el, t_max, exclude, x0, y0, cell, nx, ny, start, cell_walls,
            ax, ay, bx, by, top, z_top):
    """Whether a ray from (ox, oy, oz) with horizontal unit direction (dx, dy) and slope ``tan_el`` meets a wall
    (other than ``exclude``) within horizontal distance ``t_max``."""
    if oz >= z_top:
        return False
    if tan_el > 0.0:
        t_max = min(t_max, (z_top - oz) / tan_el)
    # clip the trace [0, t_max] to the grid's box
    t0, t1 = 0.0, t_max
    xmax, ymax = x0 + nx * cell, y0 + ny * cell
    if dx != 0.0:
        ta, tb = (x0 - ox) / dx, (xmax - ox) / dx
        t0, t1 = max(t0, min(ta, tb)), min(t1, max(ta, tb))
    elif ox < x0 or ox > xmax:
        return False
    if dy != 0.0:
        ta, tb = (y0 - oy) / dy, (ymax - oy) / dy
        t0, t1 = max(t0, min(ta, tb)), min(t1, max(ta, tb))
    elif oy < y0 or oy > ymax:
        return False
    if t0 > t1:
        return False
    ix = min(max(int(math.floor((ox + t0 * dx - x0) / cell)), 0), nx - 1)
    iy = min(max(int(math.floor((oy + t0 * dy - y0) / cell)), 0), ny - 1)
    sx = 1 if dx > 0.0 else -1
    sy = 1 if dy > 0.0 else -1
    if dx != 0.0:
        tx = (x0 + (ix + (1 if dx > 0.0 else 0)) * cell - ox) / dx
        ddx = cell / abs(dx)
    else:
        tx, ddx = _INF, _INF
    if dy != 0.0:
        ty = (y0 + (iy + (1 if dy > 0.0 else 0)) * cell - oy) / dy
        ddy = cell / abs(dy)
    else:
        ty, ddy = _INF, _INF
    while True:
        k = ix * ny + iy
        if _hits(ox, oy, oz, dx, dy, tan_el, t_max, exclude, start[k], start[k + 1], ax, ay, bx, by, top,
                 cell_walls):
            return True
        if tx < ty:
            if tx > t1:
                return False
            ix += sx
            tx += ddx
        else:
            if ty > t1:
                return False
            iy += sy
            ty += ddy
        if ix < 0 or ix >= nx or iy < 0 or iy >= ny:
            return False


@numba.njit(cache=True, nogil=True)
def _near_walls(px, py, range_m, x0, y0, cell, nx, ny, start, cell_walls, stamp, mark, near):
    """Fill ``near`` with the walls in the cells within ``range_m`` of (px, py) (each once, using ``stamp``
    marked with ``mark``); returns their number."""
    n_near = 0
    i0 = max(int(math.floor((px - range_m - x0) / cell)), 0)
    i1 = min(int(math.floor((px + range_m - x0) / cell)), nx - 1)
    j0 = max(int(math.floor((py - range_m - y0) / cell)), 0)
    j1 = min(int(math.floor((py + range_m - y0) / cell)), ny - 1)
    for i in range(i0, i1 + 1):
        for j in range(j0, j1 + 1):
            k = i * ny + j
            for q in range(start[k], start[k + 1]):
                w = cell_walls[q]
                if stamp[w] != mark:
                    stamp[w] = mark
                    near[n_near] = w
                    n_near += 1
    return n_near


@numba.njit(cache=True, nogil=True)
def _best_reflection(px, py, pz, sa, ca, ce, se, near, n_near, range_m, x0, y0, cell, nx, ny, start,
                     cell_walls, ax, ay, bx, by, top, z_top):
    """The wall (-1 for none) and extra path (m) of the shortest valid reflection among the walls ``near``."""
    te = se / ce
    best, best_w = _INF, -1
    for q in range(n_near):
        w = near[q]
        ex, ey = bx[w] - ax[w], by[w] - ay[w]
        length = math.sqrt(ex * ex + ey * ey)
        nx_, ny_ = ey / length, -ex / length
        d = nx_ * (px - ax[w]) + ny_ * (py - ay[w])
        if d < 0.0:
            nx_, ny_, d = -nx_, -ny_, -d
        nu = ce * (nx_ * sa + ny_ * ca)               # n . u
        if d <= _EPS_T or nu <= 0.0:
            continue
        ext = 2.0 * d * nu
        if ext >= best:
            continue
        s = d / nu                                    # antenna -> Q along u'
        hx, hy = ce * sa - 2.0 * nu * nx_, ce * ca - 2.0 * nu * ny_   # horizontal part of u'
        qx, qy, qz = px + s * hx, py + s * hy, pz + s * se
        if qz >= top[w] or s * ce > range_m:
            continue
        lam = ((qx - ax[w]) * ex + (qy - ay[w]) * ey) / (length * length)
        if lam < 0.0 or lam > 1.0:
            continue
        if blocked(px, py, pz, hx / ce, hy / ce, te, s * ce, w, x0, y0, cell, nx, ny, start, cell_walls,
                   ax, ay, bx, by, top, z_top):
            continue
        if blocked(qx, qy, qz, sa, ca, te, _INF, w, x0, y0, cell, nx, ny, start, cell_walls, ax, ay, bx, by,
                   top, z_top):
            continue
        best, best_w = ext, w
    return best_w, best


@numba.njit(cache=True, nogil=True, parallel=True)
def trace(pos, az, el, x0, y0, cell, nx, ny, start, cell_walls, ax, ay, bx, by, top, range_m, reflections):
    """Direct blocking and the best reflection for antennas at ``pos`` (M, A, 3) m and satellites at ``az``,
    ``el`` (M, A, C) rad. Returns ``direct_blocked`` (M, A, C) bool, ``wall`` (M, A, C) int64 (the reflecting
    wall, -1 for none) and ``extra`` (M, A, C) m (the reflected path's extra length, NaN for none). Rays with a
    non-finite or non-positive elevation are left unblocked without reflection. Epochs run in parallel; each
    result depends on its own ray only, so the output does not depend on the thread count."""
    m_n, a_n, c_n = az.shape
    w_n = top.size
    z_top = top.max() if w_n else -_INF
    direct = np.zeros((m_n, a_n, c_n), dtype=np.bool_)
    wall = np.full((m_n, a_n, c_n), -1, dtype=np.int64)
    extra = np.full((m_n, a_n, c_n), np.nan)
    for m in numba.prange(m_n):
        stamp = np.zeros(w_n, dtype=np.int64)
        near = np.empty(w_n, dtype=np.int64)
        for a in range(a_n):
            px, py, pz = pos[m, a, 0], pos[m, a, 1], pos[m, a, 2]
            n_near = 0
            if reflections and pz < z_top:
                n_near = _near_walls(px, py, range_m, x0, y0, cell, nx, ny, start, cell_walls, stamp, a + 1, near)
            for c in range(c_n):
                e = el[m, a, c]
                if not (e > 0.0):
                    continue
                sa, ca = math.sin(az[m, a, c]), math.cos(az[m, a, c])
                ce, se = math.cos(e), math.sin(e)
                direct[m, a, c] = blocked(px, py, pz, sa, ca, se / ce, _INF, -1, x0, y0, cell, nx, ny, start,
                                          cell_walls, ax, ay, bx, by, top, z_top)
                if n_near:
                    w, ext = _best_reflection(px, py, pz, sa, ca, ce, se, near, n_near, range_m, x0, y0, cell,
                                              nx, ny, start, cell_walls, ax, ay, bx, by, top, z_top)
                    if w >= 0:
                        wall[m, a, c] = w
                        extra[m, a, c] = ext
    return direct, wall, extra
