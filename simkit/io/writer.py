"""Writing the simkit HDF5 file (schema v1: :mod:`.schema`, README "HDF5 layout"): chunked, gzip-compressed, appended in time blocks.

Time series are compressed chunk by chunk by the threads of a :class:`simkit.lane.Lane`, the writing thread too
while it waits for them (byte shuffle + deflate in zlib format, which is what HDF5's shuffle and deflate filters
read, so any HDF5 reader decodes them; the byte planes that do not compress are stored in the deflate stream as they
are: :mod:`.shuffle_deflate`) and stored with direct chunk writes. Deflate releases the GIL, so compression runs
beside the simulation. The file is written under a temporary name
in the destination folder and renamed only when complete, so an interrupted run never leaves a truncated file
under the output name.
"""
from __future__ import annotations

import json
import os
from collections import deque
from concurrent.futures import Future
from datetime import datetime, timezone
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..atomic import remove_stale_temporaries, temporary_name
from ..lane import Lane, default_threads
from ..version import __version__
from . import schema
from .schema import SCHEMA_VERSION
from .shuffle_deflate import shuffle_deflate

if TYPE_CHECKING:  # h5py is imported when a file opens: a run starts its truth while h5py loads (25 ms)
    import h5py

CHUNK_ROWS = 1 << 16  # time samples per chunk along the first axis
# A series whose first chunk deflates to more than this fraction of its bytes is stored raw: its chunks skip the
# filters (HDF5's per-chunk filter mask, which every reader honours). Noise barely compresses (white noise 0.89,
# the STIM300's accelerometer 0.82, level-1 shuffle + deflate) while deflating it costs more CPU than the bytes
# saved cost to write; smooth truth (0.2-0.7) and constant terms (0.001) stay compressed.
COMPRESS_MAX_RATIO = 0.8
SKIP_FILTERS = 0b11  # filter mask of a raw chunk: shuffle and deflate skipped
# Bytes of chunks queued for compression at most (bounds memory): about two blocks of a truth + IMU run, so the
# caller goes on with the next block while the pool compresses this one instead of waiting for it.
IN_FLIGHT_BYTES = 64 << 20


def _chunks(shape, itemsize):
    rows = max(1, min(CHUNK_ROWS, (1 << 21) // max(1, itemsize * int(np.prod(shape[1:], dtype=np.int64)))))
    return (rows,) + tuple(shape[1:])


def _all_zero(chunk: np.ndarray) -> bool:
    """Whether every byte of ``chunk`` is zero (-0.0 is not): its first element decides at once for most chunks."""
    raw = chunk.reshape(-1).view(np.uint8)
    return not raw[:chunk.itemsize].any() and not raw.any()


def _deflated(chunk: np.ndarray, valid: int) -> bytes | None:
    """The stored bytes of a compressed series' chunk, or None when all its bytes are zero: such a chunk is not
    written (HDF5 reads a chunk never written as the dataset's fill value, 0), e.g. the saturation term of an IMU
    that never saturates."""
    return None if _all_zero(chunk) else shuffle_deflate(chunk, valid)


def _first_chunk(chunk: np.ndarray, valid: int) -> tuple[bytes | np.ndarray | None, int]:
    """(what to store, filter mask) of a series' first chunk (``valid`` rows before its padding): shuffled and
    deflated (None when all zero, as :func:`_deflated`), or raw when that does not pay (COMPRESS_MAX_RATIO); the
    series follows this choice."""
    packed = _deflated(chunk, valid)
    if packed is None:
        return None, 0
    return (chunk, SKIP_FILTERS) if len(packed) > COMPRESS_MAX_RATIO * chunk.nbytes else (packed, 0)


class _Series:
    """A growing dataset: rows waiting for a full chunk, and chunks being compressed."""

    def __init__(self, ds: h5py.Dataset):
        self.ds = ds
        self.rows = ds.chunks[0]
        self.tail, self.dtype = ds.shape[1:], ds.dtype  # kept here: h5py's ds.shape asks HDF5 each time
        self.capacity = 0                              # rows of the dataset's extent, whole chunks while growing
        self.pending: list[np.ndarray] = []            # the writer's own copies
        self.n_pending = 0
        self.n_total = 0
        self.n_chunks = 0
        self.raw: bool | None = None  # decided on the first chunk (COMPRESS_MAX_RATIO)
        self.probe: Future | None = None  # the first chunk's job, until that decision is read from it


class Writer:
    """Context manager writing one simkit file; ``append`` grows time series block by block."""

    def __init__(self, path: str | Path, attrs: dict, threads: int | None = None, lane: Lane | None = None):
        """``lane``: the threads that compress (the caller's own, shared with other work); without one, the writer
        has its own of ``threads`` threads, this one included (default :func:`simkit.lane.default_threads`)."""
        self.path = Path(path)
        self.tmp = temporary_name(self.path)
        self.attrs = attrs
        self.file: h5py.File | None = None
        self._series: dict[str, _Series] = {}
        self._jobs: deque = deque()  # (dataset, offset, job, filter mask or None, bytes held), in order
        self._held = 0               # bytes of the chunks in self._jobs
        self._own_lane = lane is None
        self._lane = Lane((default_threads() if threads is None else threads) - 1) if lane is None else lane

    def __enter__(self) -> "Writer":
        remove_stale_temporaries(self.path)
        import h5py

        self.file = h5py.File(self.tmp, "w")
        f = self.file
        f.attrs["schema_version"] = SCHEMA_VERSION
        f.attrs["simkit_version"] = __version__
        f.attrs["created_utc"] = datetime.now(timezone.utc).isoformat(timespec="seconds")
        for k, v in self.attrs.items():
            f.attrs[k] = v
        return self

    def __exit__(self, exc_type, exc, tb):
        try:
            if exc_type is None:
                for series in self._series.values():
                    # the exact extent before the padded last chunk is written: shrinking past a written chunk
                    # would make HDF5 rewrite it through its filters
                    series.ds.resize(series.n_total, axis=0)
                    self._flush(series, final=True)
                self._drain(0)
            if self._own_lane:
                self._lane.shutdown(wait=True, cancel_futures=True)
            self.file.close()
        finally:
            if exc_type is None:
                os.replace(self.tmp, self.path)
            else:
                self.tmp.unlink(missing_ok=True)
        return False

    @staticmethod
    def _options(shape, dtype):
        return dict(chunks=_chunks(shape, np.dtype(dtype).itemsize), compression="gzip", compression_opts=1,
                    shuffle=True)

    def append(self, name: str, block: np.ndarray, attrs: dict | None = None, handed_over: bool = False) -> None:
        """Append ``block`` along axis 0 of dataset ``name`` (declared in :mod:`.schema`; created on first use,
        resizable). ``handed_over``: the caller never modifies ``block`` afterwards, so the writer may compress
        it in place of a copy."""
        block = np.asarray(block)
        if name not in self._series:
            spec = schema.check(name, block.dtype, block.shape)
            shape = (0,) + block.shape[1:]
            ds = self.file.create_dataset(name, shape=shape, maxshape=(None,) + block.shape[1:], dtype=block.dtype,
                                          **self._options((CHUNK_ROWS,) + block.shape[1:], block.dtype))
            self._describe(ds, spec, attrs)
            self._series[name] = _Series(ds)
        series = self._series[name]
        if block.shape[1:] != series.tail or block.dtype != series.dtype:
            raise ValueError(f"{name}: block of shape {block.shape} {block.dtype} does not extend "
                             f"{(series.n_total,) + series.tail} {series.dtype}")
        series.n_total += len(block)
        if series.n_pending + len(block) < series.rows:  # no full chunk yet: keep a copy (the caller owns block)
            series.pending.append(block.copy())
            series.n_pending += len(block)
            return
        series.pending.append(block)
        series.n_pending += len(block)
        self._flush(series, final=False, handed_over=handed_over)

    def _flush(self, series: _Series, final: bool, handed_over: bool = False) -> None:
        """Send every full chunk (and, at the end, the padded last one) to compression. The last of
        ``series.pending`` may be the caller's array: it is read now or copied, never kept (unless handed over)."""
        if series.n_pending == 0 or (series.n_pending < series.rows and not final):
            return
        data = np.concatenate(series.pending) if len(series.pending) > 1 else series.pending[0]
        own = len(series.pending) > 1 or handed_over
        end = (series.n_chunks + (len(data) + series.rows - 1) // series.rows) * series.rows
        if not final and end > series.capacity:  # grow by whole chunks, 4x at a time (a resize costs ~0.4 ms)
            series.capacity = max(end, 4 * series.capacity)
            series.ds.resize(series.capacity, axis=0)
        start = 0
        while len(data) - start >= series.rows or (final and start < len(data)):
            chunk = data[start:start + series.rows]
            valid = len(chunk)
            if valid < series.rows:
                chunk = np.concatenate([chunk, np.zeros((series.rows - len(chunk),) + chunk.shape[1:], chunk.dtype)])
            else:
                chunk = np.ascontiguousarray(chunk)  # a view of a C-ordered block already is (no copy)
            offset = (series.n_chunks * series.rows,) + (0,) * (chunk.ndim - 1)
            self._encode(series, chunk, offset, own or valid < series.rows, valid)
            series.n_chunks += 1
            start += series.rows
        rest = data[start:]
        series.pending = [rest.copy()] if len(rest) else []
        series.n_pending = len(rest)
        self._drain(IN_FLIGHT_BYTES)

    def _encode(self, series: _Series, chunk: np.ndarray, offset: tuple, own: bool, valid: int) -> None:
        """Write the chunk raw now when the series' first chunk showed that deflating does not pay, else queue it
        for compression on the lane (``own``: ``chunk`` is the writer's; otherwise the lane gets a copy; ``valid``:
        its rows before the zero padding of the last chunk). The first chunk is tried on the lane too; the series
        waits for that answer only at its second chunk."""
        if series.raw is None and series.probe is not None:
            series.raw = self._lane.wait(series.probe)[1] == SKIP_FILTERS
            series.probe = None
        if series.raw:  # written at once from the array itself, ahead of chunks still compressing (any order)
            series.ds.id.write_direct_chunk(offset, chunk, filter_mask=SKIP_FILTERS)
            return
        if not own and self._lane.workers:  # a job of a lane without workers runs before submit returns
            chunk = chunk.copy()
        if series.raw is None:
            series.probe = self._lane.submit(_first_chunk, chunk, valid)
            self._jobs.append((series.ds, offset, series.probe, None, chunk.nbytes))
        else:
            self._jobs.append((series.ds, offset, self._lane.submit(_deflated, chunk, valid), 0,
                               chunk.nbytes))
        self._held += chunk.nbytes

    def _drain(self, keep: int) -> None:
        """Write finished chunks in order, keeping at most ``keep`` bytes of chunks in flight (bounds memory)."""
        while self._jobs and (self._held > keep or self._jobs[0][2].done()):
            ds, offset, job, mask, held = self._jobs.popleft()
            data = self._lane.wait(job)
            if mask is None:  # a first chunk's job: (what to store, its filter mask)
                data, mask = data
            if data is not None:
                ds.id.write_direct_chunk(offset, data, filter_mask=mask)
            self._held -= held

    def write(self, name: str, data, attrs: dict | None = None) -> None:
        """Write a whole (small, time-independent) dataset declared in :mod:`.schema`."""
        data = np.asarray(data)
        spec = schema.check(name, data.dtype, data.shape)
        if data.dtype.kind in "UO":
            import h5py

            data = data.astype(h5py.string_dtype())
        self._describe(self.file.create_dataset(name, data=data), spec, attrs)

    @staticmethod
    def _describe(ds, spec: schema.Field, attrs: dict | None) -> None:
        ds.attrs["units"] = spec.units
        if spec.frame:
            ds.attrs["frame"] = spec.frame
        for k, v in (attrs or {}).items():
            ds.attrs[k] = v

    def group_attrs(self, group: str, attrs: dict) -> None:
        """Set attributes on ``group`` (created if needed); non-scalar values are stored as JSON text."""
        g = self.file.require_group(group)
        for k, v in attrs.items():
            g.attrs[k] = v if isinstance(v, (str, int, float, np.number)) else json.dumps(v)
