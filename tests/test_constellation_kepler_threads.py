"""kepler.propagate runs small calls on one thread and large ones on numba's thread team: both kernels give the
same arrays bit for bit (one formula per element), so a result does not depend on the size of the call."""
import numpy as np

from simkit.constellation import kepler, load


def test_serial_and_parallel_kernels_agree_bit_for_bit():
    const = load("BRDM00DLR_S_20261170000_01D_MN.rnx.gz", systems="G,C")
    s = len(const.sat_ids)
    t = const._seconds(np.full(3000, 2416), 76400.0 + np.arange(3000.0) * 40.0)[1]     # beyond the file at both ends
    idx, t_eval = const.select(np.ascontiguousarray(np.broadcast_to(t[:, None], (t.size, s))))
    idx, t_eval = idx.ravel(), t_eval.ravel()
    assert (idx < 0).any() and (idx >= 0).sum() > 100_000
    outs = []
    for kernel in (kepler._propagate, kepler._propagate_serial):
        pos, clk, vel, drift = np.empty((idx.size, 3)), np.empty(idx.size), np.empty((idx.size, 3)), np.empty(idx.size)
        kernel(np.ascontiguousarray(const.records.params), idx, t_eval, True, pos, clk, vel, drift)
        outs.append((pos, clk, vel, drift))
    for a, b in zip(*outs):
        assert np.array_equal(a, b, equal_nan=True)
    small = kepler.propagate(const.records.params, idx[:1000], t_eval[:1000], velocity=True)
    assert idx.size >= kepler.PARALLEL_MIN_STATES > 1000
    for a, b in zip(small, outs[0]):
        assert np.array_equal(a, b[:1000], equal_nan=True)
