"""Writing the simkit HDF5 file (schema v1, DESIGN.md): chunked, gzip-compressed, appended in time blocks.

The file is written under a temporary name in the destination folder and renamed only when complete, so an
interrupted run never leaves a truncated file under the output name.
"""
from __future__ import annotations

import json
import os
from datetime import datetime, timezone
from pathlib import Path

import h5py
import numpy as np

from .. import SCHEMA_VERSION, __version__

CHUNK_ROWS = 1 << 16  # time samples per chunk along the first axis


def _chunks(shape, itemsize):
    rows = max(1, min(CHUNK_ROWS, (1 << 21) // max(1, itemsize * int(np.prod(shape[1:], dtype=np.int64)))))
    return (rows,) + tuple(shape[1:])


class Writer:
    """Context manager writing one simkit file; ``append`` grows time series block by block."""

    def __init__(self, path: str | Path, attrs: dict, compression: str | None = "gzip"):
        self.path = Path(path)
        self.tmp = self.path.with_name(f".{self.path.name}.tmp-{os.getpid()}")
        self.compression = compression
        self.attrs = attrs
        self.file: h5py.File | None = None

    def __enter__(self) -> "Writer":
        self.path.parent.mkdir(parents=True, exist_ok=True)
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
            self.file.close()
        finally:
            if exc_type is None:
                os.replace(self.tmp, self.path)
            else:
                self.tmp.unlink(missing_ok=True)
        return False

    def _options(self, shape, dtype):
        opts = dict(chunks=_chunks(shape, np.dtype(dtype).itemsize))
        if self.compression:
            opts.update(compression=self.compression, compression_opts=1, shuffle=True)
        return opts

    def append(self, name: str, block: np.ndarray, units: str, attrs: dict | None = None) -> None:
        """Append ``block`` along axis 0 of dataset ``name`` (created on first use, resizable)."""
        block = np.asarray(block)
        f = self.file
        if name not in f:
            shape = (0,) + block.shape[1:]
            ds = f.create_dataset(name, shape=shape, maxshape=(None,) + block.shape[1:], dtype=block.dtype,
                                  **self._options((max(1, len(block)),) + block.shape[1:], block.dtype))
            ds.attrs["units"] = units
            for k, v in (attrs or {}).items():
                ds.attrs[k] = v
        ds = f[name]
        n = ds.shape[0]
        ds.resize(n + len(block), axis=0)
        ds[n:] = block

    def write(self, name: str, data, units: str, attrs: dict | None = None) -> None:
        """Write a whole (small, time-independent) dataset."""
        data = np.asarray(data)
        if data.dtype.kind == "U":
            data = data.astype(h5py.string_dtype())
        ds = self.file.create_dataset(name, data=data)
        ds.attrs["units"] = units
        for k, v in (attrs or {}).items():
            ds.attrs[k] = v

    def group_attrs(self, group: str, attrs: dict) -> None:
        """Set attributes on ``group`` (created if needed); non-scalar values are stored as JSON text."""
        g = self.file.require_group(group)
        for k, v in attrs.items():
            g.attrs[k] = v if isinstance(v, (str, int, float, np.number)) else json.dumps(v)
