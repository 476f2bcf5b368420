"""HDF5 input/output, the only stage that knows HDF5: the schema (:mod:`.schema`), the block writer, the lazy
file object (:mod:`.dataset`), the typed readers the consumers use (:mod:`.readers`: truth, IMU, GNSS, the truth
at any epoch) and the checks on an output path.

The names below are imported from their modules on first use, so that writing a file (``simkit run``) does not
import the readers' frames and rotations."""
from __future__ import annotations

import importlib

_HOME = {
    "write_campaign_index": "campaign_index", "check_output": "output",
    "Array": "dataset", "Dataset": "dataset", "open_dataset": "dataset",
    **dict.fromkeys(("TRUTH_CORE", "Gnss", "Imu", "Truth", "broadcast_ionosphere", "gnss_signals", "has", "members",
                     "n_antennas", "n_samples", "path_of", "read_gnss", "read_imu", "read_reference", "read_truth",
                     "reference_truth", "truth_at", "truth_rows", "broadcast_time_offsets"), "readers"),
    **dict.fromkeys(("SCHEMA", "SCHEMA_VERSION", "Field", "SchemaError", "field"), "schema"),
    **dict.fromkeys(("read_solution", "solution_names", "write_solution"), "solutions"),
    "Writer": "writer",
}

__all__ = sorted(_HOME)


def __getattr__(name):
    home = _HOME.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{home}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_HOME))
