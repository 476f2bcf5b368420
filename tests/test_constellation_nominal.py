"""Every ``nominal:`` source against first principles and the published constellation definitions.

Authorities: vis-viva v^2 = mu (2/r - 1/a) and Kepler's third law T = 2 pi sqrt(a^3/mu), with each system's mu
(IS-GPS-200, BDS-SIS-ICD); the GPS SPS Performance Standard (2 revolutions per sidereal day: period
11 h 58 min); the measured GPS orbit repeat time, about 245 s short of a solar day, i.e. ~86,155 s, a few
seconds spread per satellite
(Choi et al. 2004, GRL 31 L22608; Agnew and Larson 2007, GPS Solutions 11:71); the BDS definitions (GEO slots,
IGSO equator crossings, MEO ground track repeating after 13 revolutions in 7 sidereal days).

Only positions are used (no velocities from our kernel): speeds come from central differences of positions
rotated into an inertial frame with the system's Omega_e. Tolerance for the two-body laws: a repeating ground
track with a J2-regressing node shifts the mean motion from Kepler's by the order of the J2 secular rates,
1.5 J2 (Re/a)^2 (9.4e-5 for GPS, 8.5e-5 for BDS MEO); the published radii are rounded to 0.1 km (< 6e-6).
"""
import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from simkit.constellation import load

MU = {"G": 3.986005e14, "C": 3.986004418e14, "E": 3.986004418e14, "R": 3.9860044e14}  # each system's own
OMEGA_E = {"G": 7.2921151467e-5, "C": 7.292115e-5, "E": 7.2921151467e-5, "R": 7.292115e-5}  # (ICDs)
J2, RE = 1.08262668e-3, 6378137.0
WEEK = 2416                                              # any week: nominal orbits are valid at every epoch
SOURCES = ["nominal:gps", "nominal:bds", "nominal:bds2", "nominal:bds3", "nominal:gps+bds", "nominal:gal",
           "nominal:glo", "nominal:gps+bds+gal+glo"]


def sidereal_day(system):
    """The Earth's rotation period in the system's own model, s (2 pi / Omega_e; IERS: 86164.0905 s)."""
    return 2.0 * np.pi / OMEGA_E[system]


def inertial(pos, t, system):
    """ECEF positions (N, S, 3) at times t (N,) s -> a non-rotating frame that coincides with ECEF at t = 0."""
    a = OMEGA_E[system] * t[:, None]
    out = np.empty_like(pos)
    out[..., 0] = np.cos(a) * pos[..., 0] - np.sin(a) * pos[..., 1]
    out[..., 1] = np.sin(a) * pos[..., 0] + np.cos(a) * pos[..., 1]
    out[..., 2] = pos[..., 2]
    return out


def states(const, t, system):
    """Positions of the satellites of ``system`` at seconds t of WEEK (may pass the week end)."""
    cols = const.system == system
    return const.state(WEEK, t)[0][:, cols], np.array(const.sat_ids)[cols], const.orbit_type[cols]


def ascending_nodes(z, t):
    """Interpolated times of the upward zero crossings of z (N,) sampled at t (N,)."""
    i = np.flatnonzero((z[:-1] < 0) & (z[1:] >= 0))
    return t[i] + -z[i] / (z[i + 1] - z[i]) * (t[i + 1] - t[i])


def repeat_day(a, system, inc=np.radians(55.0)):
    """Time for the Earth to turn once under a circular orbit's node regressing at the J2 secular rate
    -1.5 n J2 (Re/a)^2 cos i (n from Kepler's third law), s."""
    node_rate = -j2_scale(a) * np.sqrt(MU[system] / a**3) * np.cos(inc)
    return 2.0 * np.pi / (OMEGA_E[system] - node_rate)


def j2_scale(a):
    return 1.5 * J2 * (RE / a) ** 2


def sub_satellite(pos):
    """Ground track: the geocentric direction of each position scaled to the equatorial radius, m."""
    return RE * pos / np.linalg.norm(pos, axis=-1, keepdims=True)


def off_track(const, system, t_later, lag, half=300.0, step=2.0):
    """Distance (K, S) m from the ground-track points at ``t_later`` (K,) to the track flown ``lag`` s earlier:
    the polyline (chords between samples ``step`` s apart) over +-``half`` s around ``t_later - lag``."""
    points = sub_satellite(states(const, t_later, system)[0])                      # (K, S, 3)
    around = np.asarray(t_later)[:, None] - lag + np.arange(-half, half + step, step)
    track = sub_satellite(states(const, around.ravel(), system)[0]).reshape(around.shape + points.shape[1:])
    a, ab = track[:, :-1], np.diff(track, axis=1)                                  # (K, W, S, 3)
    ap = points[:, None] - a
    len2 = (ab * ab).sum(-1)
    f = np.clip((ap * ab).sum(-1) / np.where(len2 > 0, len2, 1.0), 0.0, 1.0)  # a GEO's track is a point
    return np.linalg.norm(ap - f[..., None] * ab, axis=-1).min(axis=1)


@pytest.mark.parametrize("source", SOURCES)
def test_circular_orbits_follow_vis_viva_and_keplers_third_law(source):
    c = load(source)
    for system in np.unique(c.system):
        mu = MU[system]
        t = np.arange(0.0, 2.0 * 86400.0, 20.0)
        pos, ids, kinds = states(c, t, system)
        r = np.linalg.norm(pos, axis=-1)
        a = r.mean(axis=0)
        assert (np.ptp(r, axis=0) < 1e-3).all(), "nominal orbits are circular"
        p_i = inertial(pos, t, system)
        speed = np.linalg.norm(p_i[2:] - p_i[:-2], axis=-1) / (t[2] - t[0])
        h = t[1] - t[0]
        speed /= np.sinc(np.sqrt(mu / a**3) * h / np.pi)  # chord of a circle: exact for uniform motion
        vis_viva = np.sqrt(mu * (2.0 / r[1:-1] - 1.0 / a))
        rel_v = np.abs(speed / vis_viva - 1.0).max(axis=0)
        kepler_t = 2.0 * np.pi * np.sqrt(a**3 / mu)
        period = np.empty(len(ids))
        for s in range(len(ids)):
            nodes = ascending_nodes(p_i[:, s, 2], t)
            if kinds[s] == "GEO":  # equatorial: the inertial angle swept instead of node crossings
                u = p_i[:, s] / r[:, s, None]
                swept = np.arctan2(np.linalg.norm(np.cross(u[:-1], u[1:]), axis=-1), (u[:-1] * u[1:]).sum(-1))
                period[s] = 2.0 * np.pi * (t[-1] - t[0]) / swept.sum()
            else:
                period[s] = np.diff(nodes).mean()
        rel_t = np.abs(period / kepler_t - 1.0)
        tol = j2_scale(a)
        s = int(np.argmax(rel_t / tol))
        print(f"{source} {system}: period {ids[s]} {period[s]:.2f} s vs Kepler {kepler_t[s]:.2f} s "
              f"({rel_t[s]:.1e}, J2 scale {tol[s]:.1e}); speed vs vis-viva worst {rel_v.max():.1e}")
        assert (rel_v < tol).all() and (rel_t < tol).all()


def test_gps_period_is_half_a_sidereal_day_and_the_track_repeats_after_one():
    c = load("nominal:gps")
    t_sid = sidereal_day("G")
    t = np.arange(0.0, 3.0 * 86400.0, 10.0)
    pos, ids, _ = states(c, t, "G")
    p_i = inertial(pos, t, "G")
    for s in range(len(ids)):
        nodes = ascending_nodes(p_i[:, s, 2], t)
        # SPS PS: 2 revolutions per sidereal day (11 h 58 min); J2 makes the real one ~5 s shorter
        assert abs(np.diff(nodes).mean() - t_sid / 2) < 10.0
    # the ground track one sidereal day later lies on the first day's track (a curve: time shifts along it)
    t2 = np.arange(3600.0, 86400.0 - 3600.0, 1800.0)
    off = off_track(c, "G", t2 + t_sid, t_sid).max()
    along = np.linalg.norm(sub_satellite(states(c, t2 + t_sid, "G")[0]) - sub_satellite(states(c, t2, "G")[0]),
                           axis=-1).max()
    # and when: the lag at which the positions coincide, vs the measured GPS orbit repeat (~86,155 s)
    first = states(c, t2, "G")[0]

    def miss(lag):
        return np.linalg.norm(states(c, t2 + lag, "G")[0] - first, axis=-1).max()

    best = minimize_scalar(miss, bounds=(t_sid - 30.0, t_sid + 30.0), method="bounded",
                           options={"xatol": 1e-4}).x
    print(f"GPS ground track after one sidereal day ({t_sid:.2f} s): max {off:.1f} m off the previous "
          f"day's track ({along / 1e3:.1f} km along it); positions repeat after {best:.2f} s "
          f"({t_sid - best:.1f} s early; miss there {miss(best):.3f} m)")
    assert off < 1000.0
    assert abs(best - 86155.0) < 5.0 and miss(best) < 1.0
    assert miss(repeat_day(26559.7e3, "G")) < 0.01  # the J2 repeat day: 2 revolutions relative to the node


def test_bds_geos_stay_in_their_longitude_slots():
    slots = {"C01": 140.0, "C02": 80.0, "C03": 110.5, "C04": 160.0, "C05": 58.75,   # BDS-2 (CSNO)
             "C59": 140.0, "C60": 80.0, "C61": 110.5}                                # BDS-3
    t = np.arange(0.0, 10.0 * 86400.0, 900.0)
    seen = set()
    for source in ("nominal:bds2", "nominal:bds3", "nominal:bds"):
        pos, ids, kinds = states(load(source), t, "C")
        for s in np.flatnonzero(kinds == "GEO"):
            lon = np.degrees(np.arctan2(pos[:, s, 1], pos[:, s, 0]))
            lat = np.degrees(np.arcsin(pos[:, s, 2] / np.linalg.norm(pos[:, s], axis=-1)))
            height = np.linalg.norm(pos[:, s], axis=-1) - RE
            assert np.abs(lon - slots[ids[s]]).max() < 1e-6 and np.abs(lat).max() < 1e-6, ids[s]
            assert np.abs(height - 35786e3).max() < 1.0
            seen.add(ids[s])
    assert seen == set(slots)


@pytest.mark.parametrize("source, crossings", [
    ("nominal:bds2", {"C06": 118.0, "C07": 118.0, "C08": 118.0, "C09": 95.0, "C10": 95.0}),
    ("nominal:bds3", {"C38": 118.0, "C39": 118.0, "C40": 118.0}),
])
def test_bds_igso_figure_eight_crosses_its_longitude_and_repeats_each_sidereal_day(source, crossings):
    c = load(source)
    t_sid = sidereal_day("C")
    t = np.arange(0.0, t_sid, 60.0)
    pos, ids, kinds = states(c, t, "C")
    later, _, _ = states(c, t + t_sid, "C")
    inc = np.radians(55.0)
    u = np.linspace(0.0, 2 * np.pi, 100001)
    # geosynchronous circular orbit, node fixed in ECEF: lon - lon_node = atan2(cos i sin u, cos u) - u
    half_width = np.degrees(np.abs(np.angle(np.exp(1j * (np.arctan2(np.cos(inc) * np.sin(u), np.cos(u)) - u))))
                            ).max()
    igso = np.flatnonzero(kinds == "IGSO")
    assert {ids[s] for s in igso} == set(crossings)
    for s in igso:
        repeat = np.linalg.norm(later[:, s] - pos[:, s], axis=-1).max()
        lon = np.degrees(np.arctan2(pos[:, s, 1], pos[:, s, 0]))
        lat = np.degrees(np.arcsin(pos[:, s, 2] / np.linalg.norm(pos[:, s], axis=-1)))
        k = np.flatnonzero((lat[:-1] < 0) != (lat[1:] < 0))
        f = lat[k] / (lat[k] - lat[k + 1])
        cross = lon[k] + f * (lon[k + 1] - lon[k])
        assert k.size == 2, "one northbound and one southbound equator crossing a day: the eight's waist"
        assert np.abs(cross - crossings[ids[s]]).max() < 1e-3
        assert abs(np.abs(lat).max() - 55.0) < 0.01
        assert abs(lon.max() - crossings[ids[s]] - half_width) < 0.01
        assert abs(crossings[ids[s]] - lon.min() - half_width) < 0.01
        assert repeat < 1e-3, f"{ids[s]}: {repeat} m after one sidereal day"
    print(f"{source} IGSO: figure eight {2 * half_width:.2f} deg wide, latitudes +-55 deg; repeat after one "
          f"sidereal day within {repeat * 1e3:.3f} mm")


@pytest.mark.parametrize("source", ["nominal:bds2", "nominal:bds3"])
def test_bds_meo_ground_track_repeats_after_13_revolutions_in_7_sidereal_days(source):
    c = load(source)
    t_sid = sidereal_day("C")
    t = np.arange(0.0, 7.0 * t_sid, 20.0)
    pos, ids, kinds = states(c, t, "C")
    meo = np.flatnonzero(kinds == "MEO")
    p_i = inertial(pos, t, "C")
    for s in meo:
        # 13 revolutions in 7 days relative to the node, which regresses at the J2 rate (textbook secular
        # formula): 7 x 2 pi / (Omega_e - node rate), 54 s short of 7 sidereal days
        nodes = ascending_nodes(p_i[:, s, 2], t)
        assert nodes.size == 13
        assert abs(13 * np.diff(nodes).mean() - 7 * repeat_day(27906.1e3, "C")) < 1.0
    t2 = np.arange(0.0, 86400.0, 3600.0)
    off = off_track(c, "C", t2 + 7 * t_sid, 7 * t_sid)[:, meo].max()
    print(f"{source}: {meo.size} MEO; ground track 7 sidereal days later within {off * 1e3:.1f} mm of the "
          f"first day's")
    assert off < 1000.0


@pytest.mark.parametrize("source, system, a_km, inc_deg, revs, days", [
    ("nominal:gal", "E", 29600.318, 56.0, 17, 10),   # Galileo OS SDD: Walker 24/3/1, 17 revolutions in 10 days
    # GLONASS ICD: draconic period 11 h 15 min 44 s (a by Kepler's third law), 17 revolutions in 8 days
    ("nominal:glo", "R", (MU["R"] * (40544.0 / (2 * np.pi)) ** 2) ** (1 / 3) / 1e3, 64.8, 17, 8)])
def test_galileo_and_glonass_walker_geometry_and_ground_track_repeat(source, system, a_km, inc_deg, revs, days):
    c = load(source)
    t = np.arange(0.0, 86400.0, 60.0)
    pos, ids, _ = states(c, t, system)
    assert len(ids) == 24
    r = np.linalg.norm(pos, axis=-1)
    np.testing.assert_allclose(r, a_km * 1e3, rtol=1e-12)
    p_i = inertial(pos, t, system)
    normal = np.cross(p_i[0], p_i[1])
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    np.testing.assert_allclose(np.degrees(np.arccos(normal[:, 2])), inc_deg, atol=0.005)  # + node regression
    nodes = np.degrees(np.arctan2(normal[:, 0], -normal[:, 1])) % 360.0  # right ascension of each node
    planes = np.round((nodes - nodes[0]) % 360.0 / 120.0) % 3
    assert np.array_equal(np.bincount(planes.astype(int)), [8, 8, 8])
    # the ground track repeats after `days` days relative to the node: positions coincide after that span
    lag = days * repeat_day(a_km * 1e3, system, np.radians(inc_deg))
    later = states(c, t[:60] + lag, system)[0]
    assert np.linalg.norm(later - pos[:60], axis=-1).max() < 0.01
    half = 2.0 * np.pi * np.sqrt((a_km * 1e3) ** 3 / MU[system])
    assert abs(revs * half / (days * sidereal_day(system)) - 1.0) < 3 * j2_scale(a_km * 1e3)


def test_nominal_glonass_channels_are_the_iac_table_and_antipodal_slots_share_them():
    c = load("nominal:glo")
    k = dict(zip(c.sat_ids, c.channels.tolist()))
    assert all(k[f"R{s:02d}"] == k[f"R{s + 4:02d}"] for p in range(3) for s in range(8 * p + 1, 8 * p + 5))
    assert len(set(k.values())) == 12 and set(k.values()) <= set(range(-7, 7))  # 12 pairs within -7..6
    # the same table the operational satellites of the 2026 broadcast file carry in their slots
    brdm = load("BRDM00DLR_S_20261170000_01D_MN.rnx.gz", systems="R")
    same = [s for s in brdm.sat_ids if s in k]
    assert len(same) >= 20 and all(k[s] == brdm.channels[brdm.sat_ids.index(s)] for s in same)
