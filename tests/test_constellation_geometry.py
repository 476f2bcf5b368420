"""Velocities, light time / Sagnac, elevation-azimuth and DOPs against RTKLIB and central differences."""

import numpy as np

from simkit import frames
from simkit.constellation import dops, load, receiver_view, visible_count

XIAN = frames.lla_to_ecef(np.radians(34.25), np.radians(108.95), 400.0)


def test_analytic_velocity_and_drift_match_central_differences():
    """GPS, BDS MEO/IGSO/GEO (the GEO rotation included), GLONASS: d/dt of the positions and clocks we return.
    (Galileo is left out: its 10-min records put some of these epochs exactly midway between two toes.)"""
    c = load("BRDM00DLR_S_20261170000_01D_MN.rnx.gz", systems="GCR")
    sow = 86400.0 + np.arange(600.0, 86000.0, 1800.0)
    h = 0.01
    pos, clk, vel, drift = c.state(2416, sow, velocity=True)
    p_plus, c_plus = c.state(2416, sow + h)
    p_minus, c_minus = c.state(2416, sow - h)
    fd_v = (p_plus - p_minus) / (2 * h)
    fd_d = (c_plus - c_minus) / (2 * h)
    same = np.isfinite(fd_v[..., 0]) & np.isfinite(vel[..., 0])
    for kind in ("MEO", "IGSO", "GEO"):
        m = same & (c.orbit_type == kind)
        err = np.abs(vel - fd_v)[m].max()
        print(f"velocity vs central difference, {kind}: max {err:.2e} m/s; drift {np.abs(drift - fd_d)[m].max():.1e}")
        assert err < 1e-5
    assert np.abs(drift - fd_d)[same].max() < 1e-14


def _rtklib_arr(values):
    import pyrtklib

    arr = pyrtklib.Arr1Ddouble(len(values))
    for i, v in enumerate(values):
        arr[i] = float(v)
    return arr


def test_light_time_range_elevation_azimuth_and_dops_match_rtklib():
    import pyrtklib
    c = load("BRDM00DLR_S_20261170000_01D_MN.rnx.gz")
    sow = 86400.0 + np.arange(0.0, 86400.0, 3600.0)
    rx = np.repeat(XIAN[None], sow.size, 0)
    g = receiver_view(c, rx, 2416, sow)
    # RTKLIB's geodist takes the satellite at emission in the ECEF frame of emission (as satposs returns it) and
    # adds the Sagnac term to first order: on sat_pos_emission it must give our range; on sat_pos (already
    # rotated into the reception frame) it would count Earth rotation twice
    lla = frames.ecef_to_lla(XIAN)
    pos_arr = _rtklib_arr(lla)
    e = pyrtklib.Arr1Ddouble(3)
    azel = pyrtklib.Arr1Ddouble(2)
    d_rng = d_ang = d_twice = 0.0
    kinds = set()
    for m in range(sow.size):
        for s in np.flatnonzero(np.isfinite(g.range[m])):
            r = pyrtklib.geodist(_rtklib_arr(g.sat_pos_emission[m, s]), _rtklib_arr(XIAN), e)
            d_rng = max(d_rng, abs(r - g.range[m, s]))
            d_twice = max(d_twice, abs(pyrtklib.geodist(_rtklib_arr(g.sat_pos[m, s]), _rtklib_arr(XIAN), e)
                                       - g.range[m, s]))
            kinds.add(c.orbit_type[s])
            pyrtklib.satazel(pos_arr, _rtklib_arr(g.los[m, s]), azel)
            d_ang = max(d_ang, abs(azel[1] - g.elevation[m, s]),
                        abs(np.mod(azel[0] - g.azimuth[m, s] + np.pi, 2 * np.pi) - np.pi))
    print(f"vs RTKLIB geodist on sat_pos_emission: max |drange| {d_rng * 1e3:.3f} mm (on sat_pos: "
          f"{d_twice:.1f} m); satazel: max |dangle| {d_ang:.1e} rad")
    assert kinds == {"MEO", "IGSO", "GEO"}
    assert d_rng < 1e-3 and d_ang < 1e-9 and d_twice > 1.0
    assert g.sat_pos_emission.shape == g.sat_pos.shape
    np.testing.assert_array_equal(np.isnan(g.sat_pos_emission), np.isnan(g.sat_pos))
    mask = np.radians(10.0)
    ours = dops(g.elevation, g.azimuth, mask)
    dop = pyrtklib.Arr1Ddouble(4)
    for m in range(sow.size):
        ok = np.isfinite(g.elevation[m])
        az_el = np.stack([g.azimuth[m, ok], g.elevation[m, ok]], -1).ravel()
        pyrtklib.dops(int(ok.sum()), _rtklib_arr(az_el), mask, dop)
        np.testing.assert_allclose([ours[k][m] for k in "GPHV"], [dop[i] for i in range(4)], rtol=1e-9)
    n = visible_count(g.elevation, mask)
    print(f"Xi'an 2026-04-27, GPS+BDS, 10 deg mask: {n.min()}-{n.max()} satellites, "
          f"PDOP {np.nanmin(ours['P']):.2f}-{np.nanmax(ours['P']):.2f}")


def test_dops_with_one_clock_per_system_and_too_few_satellites():
    el = np.radians([[30.0, 60.0, 45.0, 80.0, 20.0, 50.0], [30.0, 60.0, 45.0, -5.0, -5.0, -5.0]])
    az = np.radians([[0.0, 90.0, 180.0, 270.0, 45.0, 200.0]] * 2)
    system = np.array(["G", "G", "G", "C", "C", "C"])
    d = dops(el, az, 0.0, system)
    assert np.isnan(d["P"][1])  # 3 satellites, 4 unknowns
    # direct least-squares geometry for epoch 0 with two clock columns
    h = np.stack([-np.cos(el[0]) * np.sin(az[0]), -np.cos(el[0]) * np.cos(az[0]), -np.sin(el[0]),
                  system == "C", system == "G"], -1).astype(float)
    q = np.linalg.inv(h.T @ h)
    np.testing.assert_allclose(d["P"][0], np.sqrt(np.trace(q[:3, :3])))
    np.testing.assert_allclose(d["G"][0], np.sqrt(np.trace(q)))
    np.testing.assert_allclose(d["T"][0], np.sqrt(q[3, 3]))
