"""Reading simkit HDF5 files lazily: :func:`open_dataset` (``simkit.open``) checks it is a simkit v1 file.

``ds["truth/pos_ecef"]`` is a :class:`Array`: shape, dtype, units and attributes without reading, numpy arrays
when sliced (``[:]``, ``[1000:2000]``) or passed to numpy. No h5py object leaves this module.
"""
from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np

from ..errors import DataFileError
from .schema import SCHEMA_VERSION


def _attr_value(value):
    """An HDF5 attribute as a plain Python value (bytes decoded, numpy scalars unwrapped)."""
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.generic):
        return value.item()
    return value


class Array:
    """A lazy view of one dataset: slicing it reads only the rows asked for and returns a numpy array."""

    def __init__(self, ds: h5py.Dataset):
        self._ds = ds
        self.name = ds.name.lstrip("/")
        self.shape = ds.shape
        self.dtype = ds.dtype if h5py.check_string_dtype(ds.dtype) is None else np.dtype(object)
        self.attrs = {k: _attr_value(v) for k, v in ds.attrs.items()}
        self.units = self.attrs.get("units", "")

    @property
    def ndim(self) -> int:
        return len(self.shape)

    def __len__(self) -> int:
        return self.shape[0] if self.shape else 0

    def __getitem__(self, key) -> np.ndarray:
        if h5py.check_string_dtype(self._ds.dtype) is not None:
            return np.asarray(self._ds.asstr()[key], dtype=str)
        return np.asarray(self._ds[key])

    def __array__(self, dtype=None, copy=None):
        data = self[()]
        return data.astype(dtype) if dtype is not None else data

    def __repr__(self) -> str:
        return f"<simkit array {self.name} {self.shape} {self.dtype} [{self.units}]>"


class Dataset:
    """A read-only simkit file: ``ds[path]`` gives an :class:`Array`; ``ds.attrs`` the root attributes."""

    def __init__(self, file: h5py.File):
        self._file = file
        self.path = Path(file.filename)
        self.attrs = {k: _attr_value(v) for k, v in file.attrs.items()}

    def __getitem__(self, name: str) -> Array:
        obj = self._file.get(name)
        if not isinstance(obj, h5py.Dataset):
            what = "a group, not a dataset" if obj is not None else "no such dataset"
            raise DataFileError(self.path, f"{name}: {what}")
        return Array(obj)

    def __contains__(self, name: str) -> bool:
        return name in self._file

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def close(self):
        self._file.close()

    def group_attrs(self, group: str, decode_json: bool = False) -> dict:
        """Attributes of ``group`` (empty when absent); with ``decode_json`` JSON texts become objects."""
        g = self._file.get(group)
        if not isinstance(g, h5py.Group):
            return {}
        out = {k: _attr_value(v) for k, v in g.attrs.items()}
        if decode_json:
            for k, v in out.items():
                if isinstance(v, str) and v[:1] in "[{":
                    try:
                        out[k] = json.loads(v)
                    except ValueError:
                        pass
        return out

    def groups(self, group: str = "") -> list[str]:
        """Names of the sub-groups of ``group`` (the root by default)."""
        g = self._file.get(group or "/")
        return [k for k, v in g.items() if isinstance(v, h5py.Group)] if isinstance(g, h5py.Group) else []

    def members(self, group: str) -> list[str]:
        """Names of the datasets directly under ``group`` (empty when absent)."""
        g = self._file.get(group)
        return [k for k, v in g.items() if isinstance(v, h5py.Dataset)] if isinstance(g, h5py.Group) else []

    @property
    def scenario_name(self) -> str:
        return str(self.attrs.get("scenario_name", "?"))

    def datasets(self) -> list[tuple[str, Array]]:
        """Every dataset in the file as (path, :class:`Array`), in file order."""
        out = []
        self._file.visititems(lambda name, obj: out.append((name, Array(obj))) if isinstance(obj, h5py.Dataset)
                              else None)
        return out

    def rate_hz(self, group: str) -> float | None:
        """Sample rate of ``group/t`` (Hz), from its first two samples."""
        name = f"{group}/t"
        if name not in self._file or self._file[name].shape[0] < 2:
            return None
        t = self._file[name][:2]
        return float(1.0 / (t[1] - t[0]))

    def duration_s(self, group: str) -> float | None:
        name = f"{group}/t"
        if name not in self._file or self._file[name].shape[0] == 0:
            return None
        t = self._file[name]
        return float(t[-1] - t[0])


def open_dataset(path) -> Dataset:
    """Open a simkit file; a clear :class:`DataFileError` for missing, non-HDF5, non-simkit or other-schema files."""
    path = Path(path)
    if path.is_dir():
        raise DataFileError(path, "is a directory, expected a simkit HDF5 file")
    if not path.is_file():
        raise DataFileError(path, "no such file")
    try:
        f = h5py.File(path, "r")
    except OSError:
        with open(path, "rb") as raw:
            signed = raw.read(8) == b"\x89HDF\r\n\x1a\n"
        raise DataFileError(path, "a damaged or truncated HDF5 file (an interrupted copy?)" if signed
                            else "not an HDF5 file") from None
    version = f.attrs.get("schema_version")
    if version is None:
        f.close()
        raise DataFileError(path, "not a simkit file (no schema_version attribute)")
    if int(version) != SCHEMA_VERSION:
        f.close()
        raise DataFileError(path, f"schema version {int(version)}, this simkit reads version {SCHEMA_VERSION}")
    return Dataset(f)
