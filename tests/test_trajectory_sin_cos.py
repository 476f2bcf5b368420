"""The truth's sines and cosines from the tangent of the half angle (simkit.trajectory.truth.sin_cos, trig) against
math.sin and math.cos (the C library's, correctly rounded in practice) at any angle the truth meets: within 3e-16,
a few units in the last place."""
import math

import numpy as np

from simkit.trajectory.truth import sin_cos, trig


def _angles():
    rng = np.random.default_rng(11)
    special = np.array([0.0, -0.0, 1e-300, math.pi, -math.pi, math.pi / 2, 2 * math.pi, 3 * math.pi,
                        np.nextafter(math.pi, 0.0), np.nextafter(math.pi, 4.0), 1e5 * math.pi])
    return np.concatenate([special, rng.uniform(-7.0, 7.0, 20_000), rng.uniform(-200.0, 200.0, 5_000),
                           rng.uniform(-1e-6, 1e-6, 1_000), math.pi + rng.uniform(-1e-9, 1e-9, 1_000)])


def test_sin_cos_agree_with_the_c_library_to_a_few_ulp():
    x = _angles()
    s, c = sin_cos(x)
    ref_s = np.array([math.sin(v) for v in x])
    ref_c = np.array([math.cos(v) for v in x])
    assert np.all(np.isfinite(s)) and np.all(np.isfinite(c))
    assert np.abs(s - ref_s).max() <= 3e-16 and np.abs(c - ref_c).max() <= 3e-16
    small = np.abs(x) < 1e-6                                       # relative accuracy where sin x ~ x
    assert np.all(np.abs(s[small] - ref_s[small]) <= 4e-16 * np.abs(ref_s[small]))


def test_trig_gives_the_angle_and_its_half():
    x = _angles()
    t = trig(x)
    for got, ref, bound in ((t.half_sin, np.sin(x / 2), 3e-16), (t.half_cos, np.cos(x / 2), 3e-16),
                            (t.sin, np.sin(x), 8e-16), (t.cos, np.cos(x), 8e-16)):  # double angles: 3 more roundings
        assert np.abs(got - ref).max() <= bound
    assert np.abs(t.half_sin**2 + t.half_cos**2 - 1.0).max() <= 6e-16
