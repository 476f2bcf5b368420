"""simkit.gnss.orbit_range: the range error of an orbit error at each antenna, against its definition evaluated
with numpy (the RAC axes of ephemeris_errors.rac_axes, the error turned into ECEF, |x + d| - |x|), its first-order
form (the error projected on the line of sight) and NaN where a satellite has no state."""
import numpy as np

from simkit.earth import EARTH_RATE_ECEF
from simkit.gnss.ephemeris_errors import rac_axes
from simkit.gnss.orbit_range import range_errors


def _case(seed=5, m=40, a=3, c=11):
    rs = np.random.default_rng(seed)
    pos = rs.standard_normal((m, c, 3))
    pos *= rs.uniform(2.6e7, 4.2e7, (m, c, 1)) / np.linalg.norm(pos, axis=-1, keepdims=True)
    vel = rs.normal(0.0, 3000.0, (m, c, 3))
    v_in = vel + np.cross(EARTH_RATE_ECEF, pos)
    los = rs.standard_normal((m, a, c, 3))
    los /= np.linalg.norm(los, axis=-1, keepdims=True)
    rng = rs.uniform(2.0e7, 4.0e7, (m, a, c))
    rng[3, 1, 4] = np.nan                                     # no state
    rel = vel[:, None] - rs.normal(0.0, 100.0, (m, a, 1, 3))
    rac, rac_rate = rs.normal(0.0, 2.0, (m, c, 3)), rs.normal(0.0, 1e-3, (m, c, 3))
    return los, rng, rel, pos, vel, v_in, rac, rac_rate


def test_range_errors_equal_the_array_definition():
    los, rng, rel, pos, vel, v_in, rac, rac_rate = case = _case()
    steps = np.array([0.0, 0.5, -0.5])
    got = range_errors(*case, steps)
    for j, s in enumerate(steps):
        d = np.einsum("mcki,mck->mci", rac_axes(pos + s * vel, v_in), rac + s * rac_rate)
        x = los * rng[..., None] + s * rel
        want = np.linalg.norm(x + d[:, None], axis=-1) - np.linalg.norm(x, axis=-1)
        assert np.array_equal(np.isnan(got[j]), np.isnan(want))
        assert np.nanmax(np.abs(got[j] - want)) < 1e-8      # m: rounding of |x| ~ 4e7 m (ulp 7e-9 m)
    assert np.isnan(got[:, 3, 1, 4]).all() and np.isfinite(got).sum() == got.size - 3


def test_range_error_is_the_projection_on_the_line_of_sight_to_first_order():
    los, rng, rel, pos, vel, v_in, rac, rac_rate = case = _case(6)
    got = range_errors(*case, np.array([0.0]))[0]
    d = np.einsum("mcki,mck->mci", rac_axes(pos, v_in), rac)
    assert np.allclose(np.linalg.norm(d, axis=-1), np.linalg.norm(rac, axis=-1), rtol=1e-12)   # orthonormal axes
    bound = (rac ** 2).sum(-1).max() / (2.0 * 2.0e7) + 1e-7   # |d|^2 / (2 |x|)
    assert np.nanmax(np.abs(got - np.einsum("maci,mci->mac", los, d))) < bound
