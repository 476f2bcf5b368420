"""The truth ionosphere's compiled pass (simkit/gnss/iono_steps.py): its Klobuchar delays and pierce points
against RTKLIB (ionmodel, ionppp) and against the array expressions of simkit.gnss.atmosphere and iono_truth that
it replaces, over random geometries with the poles, negative latitudes and missing values included."""
import numpy as np
import pyrtklib as rtk

from simkit.gnss import atmosphere
from simkit.gnss.iono_steps import klobuchar_and_pierce_points
from simkit.gnss.iono_truth import SHELL_HEIGHT_M, SHELL_RADIUS_M, pierce_point
from simkit.gpstime import BDT_MINUS_GPST

STEPS = np.array([-0.05, 0.0, 0.05])
GPS = (atmosphere.DEFAULT_GPS_ALPHA, atmosphere.DEFAULT_GPS_BETA)
BDS = (atmosphere.DEFAULT_BDS_ALPHA, atmosphere.DEFAULT_BDS_BETA)


def _arr(values):
    a = rtk.Arr1Ddouble(len(values))
    for i, v in enumerate(values):
        a[i] = float(v)
    return a


def _geometry(seed, m=30, n_ant=3, c=9):
    rs = np.random.default_rng(seed)
    lat = rs.uniform(-1.5, 1.5, (m, n_ant))
    lat[:3] = np.radians([[75.0], [-80.0], [89.0]])          # over-the-pole lines of sight
    lon = rs.uniform(-np.pi, np.pi, (m, n_ant))
    lat_rate, lon_rate = rs.normal(0, 1e-5, (m, n_ant)), rs.normal(0, 1e-5, (m, n_ant))
    az, el = rs.uniform(0, 2 * np.pi, (m, n_ant, c)), rs.uniform(0.02, 1.55, (m, n_ant, c))
    az_rate, el_rate = rs.normal(0, 1e-4, (m, n_ant, c)), rs.normal(0, 1e-4, (m, n_ant, c))
    el[4, 1, 2] = np.nan                                       # a satellite without a state
    sow = rs.uniform(0.0, 604800.0, m)
    return lat, lon, lat_rate, lon_rate, az, el, az_rate, el_rate, sow


def _array_expressions(system, coef, g):
    """Klobuchar (M, A, J, C) and pierce points (M, A, J, C, 3) from the numpy functions, step by step."""
    lat, lon, lat_rate, lon_rate, az, el, az_rate, el_rate, sow = g
    klob, pts = [], []
    for s in STEPS:
        la, lo = (lat + s * lat_rate)[..., None], (lon + s * lon_rate)[..., None]
        a, e = az + s * az_rate, el + s * el_rate
        klob.append(atmosphere.broadcast_ionosphere(system, *coef, la, lo, a, e, sow[:, None, None] + s))
        lat_p, lon_p = pierce_point(la, lo, a, e)
        r = SHELL_RADIUS_M + SHELL_HEIGHT_M
        pts.append(np.stack([r * np.cos(lat_p) * np.cos(lon_p), r * np.cos(lat_p) * np.sin(lon_p),
                             r * np.sin(lat_p)], -1))
    return np.stack(klob, 2), np.stack(pts, 2)


def _kernel(system, coef, g):
    return klobuchar_and_pierce_points(system, *coef, *g, STEPS, SHELL_RADIUS_M, SHELL_HEIGHT_M)


def test_equal_to_the_array_expressions_for_gps_and_bds_to_rounding():
    g = _geometry(0)
    for system, coef in (("G", GPS), ("C", BDS)):
        klob, pts = _kernel(system, coef, g)
        want_k, want_p = _array_expressions(system, coef, g)
        assert np.array_equal(np.isnan(klob), np.isnan(want_k)) and np.isnan(klob).sum() == 3
        assert np.array_equal(np.isnan(pts), np.isnan(want_p))
        # m: delays of 1-60 m; points on a 6.7e6 m shell (1e-13 relative). Within a few degrees of a pole (rows
        # 0-2) the pierce latitude's sine is near 1, where the arcsine of the array expression and the square root
        # here both lose digits (the problem's own conditioning): 1.5e-12 rad, the bound of the RTKLIB ionppp test
        assert np.nanmax(np.abs(klob - want_k)[3:]) < 1e-12 and np.nanmax(np.abs(pts - want_p)[3:]) < 1e-6
        assert np.nanmax(np.abs(klob - want_k)[:3]) < 1e-11 and np.nanmax(np.abs(pts - want_p)[:3]) < 1e-5


def test_gps_delay_matches_rtklib_ionmodel_and_pierce_points_match_ionppp():
    g = _geometry(1, m=12, n_ant=2, c=6)
    lat, lon, _, _, az, el, _, _, sow = g
    klob, pts = _kernel("G", GPS, g)
    ion, out = _arr(list(GPS[0]) + list(GPS[1])), rtk.Arr1Ddouble(2)
    worst_k = worst_p = 0.0
    for m, a, c in np.ndindex(az.shape):
        if not np.isfinite(el[m, a, c]):
            continue
        ref = rtk.ionmodel(rtk.gpst2time(2416, sow[m]), ion, _arr([lat[m, a], lon[m, a], 0.0]),
                           _arr([az[m, a, c], el[m, a, c]]))
        worst_k = max(worst_k, abs(klob[m, a, 1, c] - ref))
        rtk.ionppp(_arr([lat[m, a], lon[m, a], 0.0]), _arr([az[m, a, c], el[m, a, c]]), SHELL_RADIUS_M,
                   SHELL_HEIGHT_M, out)
        r = SHELL_RADIUS_M + SHELL_HEIGHT_M
        want = r * np.array([np.cos(out[0]) * np.cos(out[1]), np.cos(out[0]) * np.sin(out[1]), np.sin(out[0])])
        worst_p = max(worst_p, np.abs(pts[m, a, 1, c] - want).max())
    assert worst_k < 1e-6          # m (RTKLIB's constants: the same bound as test_gnss_models)
    assert worst_p < 1e-5          # m on the shell: 1.5e-12 rad (test_gnss_truth_errors' bound for ionppp)


def test_bds_uses_bdt_and_the_bds_shell():
    g = _geometry(2, m=6, n_ant=2, c=3)
    lat, lon, _, _, az, el, _, _, sow = g
    klob, _ = _kernel("C", BDS, g)
    want = atmosphere.klobuchar_bds(*BDS, lat[..., None], lon[..., None], az, el, sow[:, None, None] + BDT_MINUS_GPST)
    assert np.nanmax(np.abs(klob[:, :, 1] - want)) < 1e-12
