"""The writer stores a series raw when deflating its first chunk does not pay (noise), compressed otherwise; HDF5's
own reader decodes both exactly (a raw chunk carries the filter mask that skips shuffle and deflate)."""
import h5py
import numpy as np

from simkit.io.writer import CHUNK_ROWS, COMPRESS_MAX_RATIO, SKIP_FILTERS, Writer, _shuffle_deflate


def test_noise_is_stored_raw_and_smooth_truth_compressed(tmp_path):
    n = 2 * CHUNK_ROWS + 1234
    noise = np.random.default_rng(0).standard_normal((n, 3))
    t = np.arange(n) / 1000.0
    assert len(_shuffle_deflate(noise[:CHUNK_ROWS])) > COMPRESS_MAX_RATIO * noise[:CHUNK_ROWS].nbytes
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
