"""The writer stores a series raw when deflating its first chunk does not pay (noise), compressed otherwise; HDF5's
own reader decodes both exactly (a raw chunk carries the filter mask that skips shuffle and deflate)."""
import h5py
import numpy as np

from simkit.io.shuffle_deflate import shuffle_deflate
from simkit.io.writer import CHUNK_ROWS, COMPRESS_MAX_RATIO, SKIP_FILTERS, Writer


def test_noise_is_stored_raw_and_smooth_truth_compressed(tmp_path):
    n = 2 * CHUNK_ROWS + 1234
    noise = np.random.default_rng(0).standard_normal((n, 3))
    t = np.arange(n) / 1000.0
    assert len(shuffle_deflate(noise[:CHUNK_ROWS])) > COMPRESS_MAX_RATIO * noise[:CHUNK_ROWS].nbytes
    path = tmp_path / "w.h5"
    with Writer(path, {}, threads=2) as w:
        for a in range(0, n, 50_000):                      # blocks that do not align with chunks
            w.append("imu/errors/gyro_white", noise[a:a + 50_000])
            w.append("truth/t", t[a:a + 50_000])
    with h5py.File(path, "r") as f:
        white, time = f["imu/errors/gyro_white"], f["truth/t"]
        np.testing.assert_array_equal(white[...], noise)
        np.testing.assert_array_equal(time[...], t)
        assert white.compression == "gzip" and white.id.get_num_chunks() == 3
        assert {white.id.get_chunk_info(i).filter_mask for i in range(3)} == {SKIP_FILTERS}
        assert {time.id.get_chunk_info(i).filter_mask for i in range(time.id.get_num_chunks())} == {0}
        assert time.id.get_chunk_info(0).size < 0.1 * CHUNK_ROWS * 8


def test_chunk_aligned_blocks_handed_over_or_copied_and_reused_buffers(tmp_path):
    """Blocks of exactly one chunk go to the pool without a copy when handed over; a caller that reuses its buffer
    (not handed over) still gets what it appended; a series shorter than a chunk (its first chunk is the padded
    last one) and the single-thread writer give the same arrays."""
    n = 3 * CHUNK_ROWS + 10
    rng = np.random.default_rng(1)
    noise, smooth = rng.standard_normal((n, 3)), np.cumsum(np.full((n, 3), 1e-3), axis=0)
    for threads in (1, 2):
        path = tmp_path / f"a{threads}.h5"
        buffer = np.empty((CHUNK_ROWS, 3))
        with Writer(path, {}, threads=threads) as w:
            w.append("truth/t", np.arange(7) * 0.5)
            for a in range(0, n, CHUNK_ROWS):
                w.append("imu/errors/gyro_white", noise[a:a + CHUNK_ROWS].copy(), handed_over=True)
                part = smooth[a:a + CHUNK_ROWS]
                buffer[:len(part)] = part
                w.append("truth/f_ib_b", buffer[:len(part)])
                buffer[:] = -1.0                                # the caller reuses its buffer at once
        with h5py.File(path, "r") as f:
            np.testing.assert_array_equal(f["imu/errors/gyro_white"][...], noise)
            np.testing.assert_array_equal(f["truth/f_ib_b"][...], smooth)
            np.testing.assert_array_equal(f["truth/t"][...], np.arange(7) * 0.5)
            white, force = f["imu/errors/gyro_white"].id, f["truth/f_ib_b"].id
            assert white.get_num_chunks() == force.get_num_chunks() == 4
            assert {white.get_chunk_info(i).filter_mask for i in range(4)} == {SKIP_FILTERS}
            assert {force.get_chunk_info(i).filter_mask for i in range(4)} == {0}


def test_chunks_of_zero_bytes_are_not_written_and_read_back_as_zero(tmp_path):
    """A compressed series' chunk whose bytes are all zero (a saturation term that never clips) is left unwritten:
    HDF5 and h5py read it as the fill value 0. A chunk of -0.0 (not zero bytes) and a chunk that is zero but for
    its last element are written, so every bit reads back; a series that starts with a zero chunk is still
    compressed, not raw."""
    rows = CHUNK_ROWS
    data = np.zeros((5 * rows + 17, 3))
    data[rows:2 * rows] = -0.0
    data[3 * rows - 1, 2] = 1e-300
    data[4 * rows:] = np.cumsum(np.full((rows + 17, 3), 1e-3), axis=0)
    for threads in (1, 2):
        path = tmp_path / f"z{threads}.h5"
        with Writer(path, {}, threads=threads) as w:
            for a in range(0, len(data), 40_000):
                w.append("imu/errors/gyro_saturation", data[a:a + 40_000])
        with h5py.File(path, "r") as f:
            ds = f["imu/errors/gyro_saturation"]
            got = ds[...]
            assert got.view(np.uint64).tobytes() == data.view(np.uint64).tobytes()   # -0.0 keeps its sign bit
            assert ds.id.get_num_chunks() == 4                                       # chunks 1, 2, 4, 5 of 6
            written = [ds.id.get_chunk_info(i) for i in range(4)]
            assert [c.chunk_offset[0] // rows for c in written] == [1, 2, 4, 5]
            assert {c.filter_mask for c in written} == {0}
