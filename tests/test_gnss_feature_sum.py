"""The clustered random-Fourier-feature sums behind the truth ionosphere against their closed form,
sum_f cos(k_f . x + w_f t + phase_f) evaluated term by term with numpy."""
import numpy as np
import pytest

from simkit.gnss.feature_sum import REDUCE_MAX, SMALL, feature_sums
from simkit.gnss.iono_truth import TruthIonosphere

WEEK = 2416


def _closed_form(k, w, phase, x, t, dt):
    arg = x @ k.T + (t[:, None, None, None] + dt[None, None, :, None])[..., None] * w + phase
    return np.cos(arg).sum(axis=-1)


def _features(length_m=1000e3, time_s=3600.0, n=64, seed=3):
    rs = np.random.default_rng(seed)
    return rs.standard_normal((n, 3)) / length_m, rs.standard_normal(n) / time_s, rs.uniform(0, 2 * np.pi, n)


def test_clusters_of_nearby_points_equal_the_closed_form():
    k, w, phase = _features()
    rs = np.random.default_rng(0)
    base = rs.standard_normal((50, 1, 1, 20, 3)) * 4e6
    x = base + rs.standard_normal((50, 3, 3, 20, 3)) * 20.0     # antennas and time steps metres apart
    x[3, 1, 0, 4] = np.nan                                       # one member without a position
    x[7, 0, 1, 2] = np.nan                                       # one base without a position
    t, dt = 1000.0 + np.arange(50.0), np.array([-0.05, 0.0, 0.05])
    got, want = feature_sums(k, w, phase, x, t, dt), _closed_form(k, w, phase, x, t, dt)
    assert np.array_equal(np.isnan(got), np.isnan(want))
    assert np.nanmax(np.abs(got - want)) < 1e-12


def test_far_members_and_huge_phases_take_the_exact_path():
    k, w, phase = _features()
    rs = np.random.default_rng(1)
    x = rs.standard_normal((4, 2, 3, 5, 3)) * 4e6
    x[:, 1] = x[:, 0] + 5e4                       # a second point 50 km away: |d| >> SMALL
    t, dt = np.array([0.0, 10.0, 3e9, 5e9]), np.array([-1.0, 0.0, 1.0])   # phases far beyond REDUCE_MAX
    assert np.abs(w).max() * 3e9 > REDUCE_MAX and np.abs(k).max() * 5e4 > SMALL
    got, want = feature_sums(k, w, phase, x, t, dt), _closed_form(k, w, phase, x, t, dt)
    # at 1e9 s the phases are ~1e6 rad: numpy's own phase carries ~1e-10 rad of rounding
    assert np.abs(got[:2] - want[:2]).max() < 1e-12 and np.abs(got[2:] - want[2:]).max() < 1e-8


@pytest.mark.parametrize("system, alpha, beta", [
    ("G", (2.2352e-08, 1.4901e-08, -1.1921e-07, -5.9605e-08), (1.2493e05, 6.5536e04, -1.9661e05, 6.5536e04)),
    ("C", (3.3528e-08, 6.7055e-08, -1.0133e-06, 1.6093e-06), (1.1878e05, 3.2768e04, 7.8643e05, -7.8643e05))])
def test_truth_ionosphere_and_its_rate_equal_the_closed_form_field_at_every_antenna(system, alpha, beta):
    """The truth delay at three antennas 10 m apart and its central-difference rate, both from the closed-form
    field at each antenna and time step: within 1e-9 m and 1e-9 m/s; the Klobuchar delay (GPS or BDS model) within
    1e-12 m of the array expression."""
    truth = TruthIonosphere(7, 0.5, 1000e3, 3600.0)
    rs = np.random.default_rng(2)
    m, c, h = 40, 12, 0.05
    lat0, lon0 = np.radians(34.2), np.radians(108.9)
    offsets = np.array([[0.0, 0.0], [3.965, 0.0], [0.0, 9.445]]) / 6.37e6
    lla = np.zeros((m, 3, 3))
    lla[..., 0], lla[..., 1], lla[..., 2] = lat0 + offsets[:, 0], lon0 + offsets[:, 1], 420.0
    vel = np.zeros_like(lla)
    vel[..., :2] = rs.normal(0.0, 50.0, (m, 1, 2))
    az = np.broadcast_to(rs.uniform(0, 2 * np.pi, (m, 1, c)), (m, 3, c)) + rs.normal(0, 1e-6, (m, 3, c))
    el = np.broadcast_to(rs.uniform(0.2, 1.5, (m, 1, c)), (m, 3, c)) + rs.normal(0, 1e-6, (m, 3, c))
    az_rate, el_rate = rs.normal(0, 1e-4, (m, 3, c)), rs.normal(0, 1e-4, (m, 3, c))
    sow = (86400.0 + 30.0 * np.arange(m))[:, None, None]
    iono, rate, klob = truth.delay(system, alpha, beta, lla, vel, az, el, az_rate, el_rate, np.full_like(sow, WEEK),
                                   sow, sow - 86400.0)

    from simkit import earth
    from simkit.gnss.atmosphere import broadcast_ionosphere
    from simkit.gnss.iono_truth import SHELL_HEIGHT_M, SHELL_RADIUS_M, pierce_point

    f = truth.field
    lat, lon, hgt = lla[..., 0, None], lla[..., 1, None], lla[..., 2, None]
    rm, rn = earth.radii(lat)
    lat_rate, lon_rate = vel[..., 1, None] / (rm + hgt), vel[..., 0, None] / ((rn + hgt) * np.cos(lat))

    def exact(s):
        la, lo, a, e = lat + s * lat_rate, lon + s * lon_rate, az + s * az_rate, el + s * el_rate
        lat_p, lon_p = pierce_point(la, lo, a, e)
        r = SHELL_RADIUS_M + SHELL_HEIGHT_M
        x = np.stack([r * np.cos(lat_p) * np.cos(lon_p), r * np.cos(lat_p) * np.sin(lon_p), r * np.sin(lat_p)], -1)
        field = f.scale * np.cos(x @ f.k.T + (sow - 86400.0 + s)[..., None] * f.w + f.phase).sum(-1)
        k = broadcast_ionosphere(system, alpha, beta, la, lo, a, e, sow + s)
        return k * np.exp(truth.sigma * field - 0.5 * truth.sigma**2), k

    want_rate = (exact(h)[0] - exact(-h)[0]) / (2 * h)
    assert np.abs(klob - exact(0.0)[1]).max() < 1e-12
    print(f"\nmax |delay - closed form| {np.abs(iono - exact(0.0)[0]).max():.2e} m, rate "
          f"{np.abs(rate - want_rate).max():.2e} m/s")
    assert np.abs(iono - exact(0.0)[0]).max() < 1e-9 and np.abs(rate - want_rate).max() < 1e-9
    assert np.all(np.abs(iono / klob - 1.0) > 1e-6)   # the field does depart from Klobuchar
