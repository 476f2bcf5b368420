"""Per-run records (``DIR/runs/<run_id>.json``) and the content check that lets a re-run skip a completed run.

A record is written atomically (temporary name, then rename) after the run's HDF5 file is complete, and holds the
file's SHA-256, the seed, the grid overrides, the metrics, or the error of a failed run. A run counts as complete
only when its record says so, the file's digest equals the recorded one, and the file's root attributes carry
the expected effective scenario text and seed.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

from ..atomic import atomic_open
from ..errors import SimkitError
from ..io import open_dataset

RECORD_VERSION = 1


def file_digest(path) -> str:
    """SHA-256 of a file's bytes, hex."""
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def write_json_atomic(path: Path, obj) -> None:
    """Write ``obj`` as JSON to ``path`` under a temporary name, then rename: readers never see half a file."""
    text = json.dumps(obj, indent=1, allow_nan=False, default=_jsonable) + "\n"
    with atomic_open(path, "w", encoding="utf-8") as f:
        f.write(text)


def _jsonable(value):
    if hasattr(value, "item"):
        return value.item()
    raise TypeError(f"not JSON-serialisable: {type(value).__name__}")


def record_path(run_dir: Path, run_id: str) -> Path:
    return run_dir / f"{run_id}.json"


def read_record(path: Path) -> dict | None:
    """The record at ``path``, or None when absent or unreadable (it is then simply re-run)."""
    try:
        rec = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return rec if isinstance(rec, dict) and rec.get("record_version") == RECORD_VERSION else None


def file_identity(path) -> tuple[str, int | str]:
    """(effective scenario text, seed) from the root attributes of a simkit file."""
    with open_dataset(path) as ds:
        return str(ds.attrs.get("scenario_toml", "")), ds.attrs.get("seed")


def verify(record: dict | None, h5: Path, text: str, seed: int) -> str | None:
    """None when ``h5`` is the completed run that ``record`` describes with scenario ``text`` and ``seed``;
    otherwise the reason it must be run again."""
    if record is None or record.get("status") != "ok":
        return "no completed record"
    if not h5.is_file():
        return "file missing"
    if file_digest(h5) != record.get("sha256"):
        return "file differs from its record"
    try:
        stored_text, stored_seed = file_identity(h5)
    except SimkitError as exc:
        return f"unreadable: {exc}"
    if stored_text != text or str(stored_seed) != str(seed):
        return "file holds another scenario or seed"
    return None
