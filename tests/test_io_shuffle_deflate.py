"""Chunks encoded with some byte planes stored in the deflate stream (simkit.io.shuffle_deflate) against the
decoders that read them: the standard library's inflater (RFC 1950/1951, Adler-32 checked) for the stream, and
HDF5's own shuffle + deflate filters (through h5py's read of a direct-written chunk) for the chunk."""
import zlib

import h5py
import numpy as np
import pytest

from simkit.io import shuffle_deflate as sd


def _chunks():
    rng = np.random.default_rng(5)
    n = 70_000                                                     # planes longer than one stored block
    t = np.arange(n) * 1e-3
    smooth = np.stack([np.sin(0.3 * t), np.cos(0.2 * t), t * t], axis=-1)
    return {
        "noise float64": rng.standard_normal((n, 3)),               # low planes stored, exponents deflated
        "smooth float64": smooth,                                    # low mantissa planes random all the same
        "noisy then smooth": np.concatenate([rng.standard_normal((n // 2, 3)), smooth[n // 2:]]),
        "float32": (smooth + 1e-3 * rng.standard_normal(smooth.shape)).astype(np.float32),
        "int16": rng.integers(-2**15, 2**15, size=(n, 2), dtype=np.int16),
        "uint8": rng.integers(0, 255, size=(n,), dtype=np.uint8),
        "constant": np.full((n, 4), 3.25),
        "short": rng.standard_normal((5, 3)),
    }


@pytest.mark.parametrize("name", list(_chunks()))
def test_the_stream_inflates_to_the_shuffled_bytes(name):
    chunk = _chunks()[name]
    packed = sd.shuffle_deflate(chunk)
    raw = chunk.view(np.uint8).reshape(-1, chunk.dtype.itemsize)
    assert zlib.decompress(packed) == raw.T.tobytes()              # checks the header and the Adler-32 too
    assert (packed[0] * 256 + packed[1]) % 31 == 0


def test_noise_planes_are_stored_and_cost_no_more_bytes_than_deflating_them(monkeypatch):
    chunk = _chunks()["noise float64"]
    stored = []
    keep = sd._stored
    monkeypatch.setattr(sd, "_stored", lambda data: stored.append(data.size) or keep(data))
    packed = sd.shuffle_deflate(chunk)
    assert len(packed) < 1.01 * len(zlib.compress(sd.planes(chunk).tobytes(), 1))
    n = chunk.size                                                  # bytes per plane
    assert 4 <= len(stored) <= 6 and sum(stored) >= 4 * (n - int(n * sd.PROBE_FRACTION))
    stored.clear()
    sd.shuffle_deflate(_chunks()["constant"])                      # every plane compresses
    assert stored == []


def test_a_padded_last_chunk_deflates_its_zeros():
    rng = np.random.default_rng(2)
    chunk = np.zeros((65_536, 3))
    chunk[:5_000] = rng.standard_normal((5_000, 3))
    padded = sd.shuffle_deflate(chunk, valid_rows=5_000)
    assert zlib.decompress(padded) == sd.planes(chunk).tobytes()
    assert len(padded) < 1.2 * 5_000 * 3 * 8                      # not the 1.5 MB the probe's verdict would store
    assert len(sd.shuffle_deflate(chunk)) == pytest.approx(len(padded), rel=0.5)


@pytest.mark.parametrize("name", ["noise float64", "noisy then smooth", "float32", "int16", "constant"])
def test_hdf5_reads_the_chunk_through_its_own_filters(tmp_path, name):
    chunk = _chunks()[name]
    rows = chunk.shape[0]
    with h5py.File(tmp_path / "c.h5", "w") as f:
        ds = f.create_dataset("x", shape=(2 * rows,) + chunk.shape[1:], chunks=chunk.shape, dtype=chunk.dtype,
                              compression="gzip", shuffle=True)
        ds.id.write_direct_chunk((0,) * chunk.ndim, sd.shuffle_deflate(chunk), filter_mask=0)
        last = np.zeros_like(chunk)
        last[:rows // 3] = chunk[::3][:rows // 3]
        offset = (rows,) + (0,) * (chunk.ndim - 1)
        ds.id.write_direct_chunk(offset, sd.shuffle_deflate(last, valid_rows=rows // 3), filter_mask=0)
    with h5py.File(tmp_path / "c.h5", "r") as f:
        np.testing.assert_array_equal(f["x"][:rows], chunk)
        np.testing.assert_array_equal(f["x"][rows:], last)


def test_the_standard_library_deflate_writes_the_same_format(monkeypatch):
    monkeypatch.setattr(sd, "deflate", zlib)
    for chunk in _chunks().values():
        assert zlib.decompress(sd.shuffle_deflate(chunk)) == sd.planes(chunk).tobytes()
