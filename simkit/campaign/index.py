"""``DIR/index.h5``: the per-run summary table and virtual datasets over the completed run files."""
from __future__ import annotations

from pathlib import Path

from ..io import open_dataset, write_campaign_index

_TEXT = ("run_id", "status", "file", "sha256")


def index_columns(rows: list[dict]) -> dict[str, list]:
    """Column name -> R values of the per-run table (metrics as ``name.key`` columns)."""
    cols = {name: [str(r.get(name) or "") for r in rows] for name in _TEXT}
    cols.update({name: [r.get(name) for r in rows] for name in ("seed", "point", "elapsed_s")})
    keys = sorted({k for r in rows for k in r["metrics"]})
    cols.update({k: [r["metrics"].get(k) for r in rows] for k in keys})
    return cols


def write_index(out: Path, rows: list[dict], records: dict | None = None) -> list[str]:
    """Write ``out/index.h5`` for the runs ``rows``; returns the dataset paths stacked as virtual datasets.

    ``records`` (run_id -> record): the dataset layouts the workers recorded (``datasets``) are used when every
    completed run has one; otherwise (records of an older simkit) the run files are walked."""
    done = [r for r in rows if r["status"] == "ok"]
    files = [out / r["file"] for r in done]
    layouts = [(records or {}).get(r["run_id"], {}).get("datasets") for r in done]
    if files and all(isinstance(lay, dict) for lay in layouts):
        paths = list(layouts[0])
    else:
        layouts, paths = None, []
        if files:
            with open_dataset(files[0]) as ds:
                paths = [p for p, _ in ds.datasets()]
    return write_campaign_index(out / "index.h5", index_columns(rows), files, paths, layouts)
