"""simkit.gnss.columns.place_columns against its definition: a full array of the fill, the columns assigned by
fancy indexing, NaN where a signal is not tracked."""
import numpy as np

from simkit.gnss.columns import place_columns


def test_place_columns_equals_full_and_fancy_assignment():
    rs = np.random.default_rng(9)
    x = rs.standard_normal((50, 3, 6))
    x[4, 2, 1] = np.nan
    cols = np.array([0, 3, 4, 9, 10, 66])
    keep = rs.random((50, 3, 6)) > 0.2
    want = np.full((50, 3, 67), np.nan)
    want[..., cols] = np.where(keep, x, np.nan)
    assert np.array_equal(place_columns(x, cols, 67, keep), want, equal_nan=True)
    want = np.full((50, 3, 67), 0.0)
    want[..., cols] = x
    assert np.array_equal(place_columns(x, cols, 67, fill=0.0), want, equal_nan=True)
    # a value broadcast over antennas and columns, and no columns at all
    assert np.array_equal(place_columns(np.ones((50, 1, 1)), cols, 67, keep)[..., cols], np.where(keep, 1.0, np.nan),
                          equal_nan=True)
    assert np.isnan(place_columns(np.zeros((50, 3, 0)), np.zeros(0, int), 67)).all()
