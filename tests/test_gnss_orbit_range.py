"""simkit.gnss.orbit_range: the range error of an orbit error at each antenna, against its definition
|x + d| - |x| evaluated with numpy (bit for bit: the same arithmetic), NaN where a satellite has no state."""
import numpy as np

from simkit.gnss.orbit_range import range_errors


def test_range_errors_equal_the_norm_difference_bit_for_bit():
    rs = np.random.default_rng(5)
    m, a, c = 40, 3, 11
    los = rs.standard_normal((m, a, c, 3))
    los /= np.linalg.norm(los, axis=-1, keepdims=True)
    rng = rs.uniform(2.0e7, 4.0e7, (m, a, c))
    rng[3, 1, 4] = np.nan                                     # no state
    rel = rs.normal(0.0, 3000.0, (m, a, c, 3))
    steps = np.array([0.0, 0.5, -0.5])
    d = rs.normal(0.0, 2.0, (steps.size, m, c, 3))            # metre-level orbit errors
    got = range_errors(los, rng, rel, d, steps)
    for j, s in enumerate(steps):
        x = los * rng[..., None] + s * rel
        want = np.linalg.norm(x + d[j][:, None], axis=-1) - np.linalg.norm(x, axis=-1)
        assert np.array_equal(got[j], want, equal_nan=True)
    assert np.isnan(got[:, 3, 1, 4]).all() and np.isfinite(got).sum() == got.size - 3
    # and it is the projection of d on the line of sight to first order, off by at most |d|^2 / (2 |x|)
    bound = (d[0] ** 2).sum(-1).max() / (2.0 * 2.0e7) + 1e-7
    assert np.nanmax(np.abs(got[0] - np.einsum("maci,mci->mac", los, d[0]))) < bound
