"""The bytes HDF5's shuffle + deflate filters read back, for one chunk, with the byte planes that do not compress
stored instead of deflated.

HDF5's shuffle filter regroups a chunk's bytes by significance (byte 0 of every element, then byte 1, ...: one
*plane* per byte of the element); its deflate filter stores those bytes as one zlib stream (RFC 1950 around
RFC 1951). A deflate stream may mix block types: deflated blocks and *stored* blocks (BTYPE 00, the bytes
verbatim behind a 5-byte header, at most 65,535 bytes each), and every inflater reads both. In float64 series
the exponent and high mantissa planes compress well, while the low mantissa planes of anything noisy are random:
deflating them costs as much CPU as the others (about 0.26 ms for 196 kB with ISA-L level 1) and saves nothing
(ratio 1.00). So the head of each plane (its first :data:`PROBE_FRACTION`) is deflated, and the rest of the plane
is deflated by the same compressor when the head compressed, stored when it did not (:data:`STORE_RATIO`).
Each decision is the chunk's own (a series that turns from noisy to smooth compresses again at its next chunk),
and the head is part of the stream, so probing costs nothing where the plane compresses. Deflated bytes end with
a sync flush (the next block starts on a byte boundary); after stored bytes a fresh compressor starts (it refers
to nothing before it). The stream ends with an empty final stored block and the Adler-32 of the shuffled bytes.
The file's filter pipeline stays shuffle + deflate: any HDF5 reader decodes it without a plugin.

Deflate is ISA-L's (``isal``, the optional ``fast`` extra) when installed: the same format at about 13x zlib's
speed; otherwise the standard library's ``zlib``. Both release the GIL.
"""
from __future__ import annotations

import struct

import numpy as np

try:  # ISA-L writes the same zlib format as the standard library, ~13x faster
    from isal import isal_zlib as deflate
except ImportError:  # pragma: no cover - exercised by the test that hides isal
    import zlib as deflate

LEVEL = 1              # ISA-L's level 1 is both faster and smaller than its level 0 on these chunks
ZLIB_HEADER = b"\x78\x01"          # deflate, 32 kB window, "fastest" (RFC 1950: header % 31 == 0)
FINAL_BLOCK = b"\x01\x00\x00\xff\xff"  # an empty stored block with BFINAL set: the end of the deflate stream
STORED_MAX = 65535     # bytes in one stored block at most (its 16-bit LEN)
PROBE_FRACTION = 1 / 8  # of each plane, deflated to decide how to store the rest
# The rest of a plane is stored when its deflated head exceeds this fraction of the head's bytes: the mantissa
# planes of noise (1.00) and of noisy truth (0.91-0.93) are; exponent planes (0.00-0.3) and smooth series
# (0.2-0.8) are deflated.
STORE_RATIO = 0.9


def planes(chunk: np.ndarray) -> np.ndarray:
    """The byte planes of ``chunk`` (itemsize, elements) uint8, in HDF5's shuffle order (a copy)."""
    raw = np.ascontiguousarray(chunk).view(np.uint8).reshape(-1, chunk.dtype.itemsize)
    return np.ascontiguousarray(raw.T)


def _stored(data: np.ndarray) -> list:
    """Stored blocks holding the bytes ``data``."""
    parts = []
    for start in range(0, data.size, STORED_MAX):
        piece = data[start:start + STORED_MAX]
        parts += (struct.pack("<BHH", 0, piece.size, piece.size ^ 0xFFFF), piece)
    return parts


def encode(shuffled: np.ndarray, valid: int | None = None) -> bytes:
    """The zlib stream of the (itemsize, elements) ``shuffled`` planes: each plane's head deflated, its rest
    deflated or stored as the head shows. ``valid``: the elements before the zero padding of a dataset's last
    chunk (the probe looks at the data only; the zeros are always deflated, to almost nothing)."""
    valid = shuffled.shape[1] if valid is None else valid
    parts, z = [ZLIB_HEADER], None
    for plane in shuffled:
        data, padding = plane[:valid], plane[valid:]
        cut = max(1, int(data.size * PROBE_FRACTION))
        if z is None:
            z = deflate.compressobj(LEVEL, deflate.DEFLATED, -15)  # raw deflate: no header of its own
        probe = z.compress(data[:cut])
        probe += z.flush(deflate.Z_SYNC_FLUSH)
        parts.append(probe)
        if len(probe) > STORE_RATIO * cut:
            parts += _stored(data[cut:])
            z = None                   # the next deflated bytes come after stored ones: a fresh compressor
        else:
            padding = plane[cut:]      # deflated on, with the data
        if padding.size:
            z = z or deflate.compressobj(LEVEL, deflate.DEFLATED, -15)
            parts += (z.compress(padding), z.flush(deflate.Z_SYNC_FLUSH))
    parts += (FINAL_BLOCK, struct.pack(">I", deflate.adler32(shuffled)))
    return b"".join(parts)


def shuffle_deflate(chunk: np.ndarray, valid_rows: int | None = None) -> bytes:
    """What HDF5's shuffle + deflate filters decode into ``chunk`` (one chunk of a dataset; ``valid_rows``: the
    rows before its zero padding, if any)."""
    per_row = int(np.prod(chunk.shape[1:], dtype=np.int64))
    return encode(planes(chunk), None if valid_rows is None else valid_rows * per_row)
