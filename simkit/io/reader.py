"""Reading simkit HDF5 files lazily: :func:`open_dataset` (``simkit.open``) checks it is a simkit v1 file."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from .. import SCHEMA_VERSION
from ..errors import DataFileError


class Dataset:
    """A read-only simkit file. ``ds["truth/pos_ecef"]`` is a lazy h5py dataset (slice it to read)."""

    def __init__(self, file: h5py.File):
        self.file = file
        self.attrs = file.attrs
        self.path = Path(file.filename)

    def __getitem__(self, name: str):
        return self.file[name]

    def __contains__(self, name: str) -> bool:
        return name in self.file

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def close(self):
        self.file.close()

    @property
    def scenario_name(self) -> str:
        import tomllib

        try:
            return tomllib.loads(self.attrs["scenario_toml"])["scenario"]["name"]
        except Exception:  # provenance text is informative only
            return "?"

    def datasets(self) -> list[tuple[str, h5py.Dataset]]:
        """Every dataset in the file as (path, dataset), in file order."""
        out = []
        self.file.visititems(lambda name, obj: out.append((name, obj)) if isinstance(obj, h5py.Dataset) else None)
        return out

    def rate_hz(self, group: str) -> float | None:
        """Sample rate of ``group/t`` (Hz), from its first two samples."""
        name = f"{group}/t"
        if name not in self.file or self.file[name].shape[0] < 2:
            return None
        t = self.file[name][:2]
        return float(1.0 / (t[1] - t[0]))

    def duration_s(self, group: str) -> float | None:
        name = f"{group}/t"
        if name not in self.file or self.file[name].shape[0] == 0:
            return None
        t = self.file[name]
        return float(t[-1] - t[0])

    def read(self, name: str) -> np.ndarray:
        return self.file[name][...]


def open_dataset(path) -> Dataset:
    """Open a simkit file; a clear :class:`DataFileError` for missing, non-HDF5, non-simkit or other-schema files."""
    path = Path(path)
    if not path.is_file():
        raise DataFileError(path, "no such file")
    try:
        f = h5py.File(path, "r")
    except OSError:
        raise DataFileError(path, "not an HDF5 file") from None
    version = f.attrs.get("schema_version")
    if version is None:
        f.close()
        raise DataFileError(path, "not a simkit file (no schema_version attribute)")
    if int(version) != SCHEMA_VERSION:
        f.close()
        raise DataFileError(path, f"schema version {int(version)}, this simkit reads version {SCHEMA_VERSION}")
    return Dataset(f)
