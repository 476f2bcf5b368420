"""The observables' normal draws: the compiled inverse normal CDF against scipy's ``ndtri`` (Cephes), and the keyed
streams' independence of the block split."""
import numpy as np
from scipy.special import ndtri

from simkit.gnss.draws import KeyedNormals, normal_quantiles


def test_normal_quantiles_match_scipy_ndtri_in_the_centre_and_both_tails():
    gen = np.random.default_rng(7)
    u = np.concatenate([gen.random(200_000) + 2.0**-54,                     # what the draws see
                        10.0 ** -gen.uniform(1.0, 300.0, 20_000),           # deep lower tail (r > 5 included)
                        1.0 - 10.0 ** -gen.uniform(1.0, 15.0, 20_000),      # upper tail
                        [0.5, 0.075, 0.925, 0.0749999, 2.0**-54, 1.0 - 2.0**-53]])
    ours, ref = normal_quantiles(u), ndtri(u)
    rel = np.abs(ours - ref) / np.maximum(np.abs(ref), 1e-300)
    assert rel.max() < 2e-15, (u[np.argmax(rel)], rel.max())
    assert normal_quantiles(np.array([0.5]))[0] == 0.0
    assert normal_quantiles(u.reshape(-1, 2)).shape == (u.size // 2, 2)


def test_draws_do_not_depend_on_how_epochs_are_split_into_blocks():
    sats = [np.array([0, 1]), np.array([0])]
    one = KeyedNormals(11, 2, ["G01", "C01"], sats, 2).draw(0, 50, np.array([0, 1]))
    parts = KeyedNormals(11, 2, ["G01", "C01"], sats, 2)
    split = np.concatenate([parts.draw(0, 20, np.array([0, 1])), parts.draw(20, 30, np.array([0, 1]))])
    np.testing.assert_array_equal(one, split)
    assert np.all(one[:, :, 1, 1] == 0.0)                     # C01 does not transmit the second signal
    z = one[:, :, :, 0].ravel()
    assert abs(z.mean()) < 0.2 and 0.8 < z.std() < 1.2
