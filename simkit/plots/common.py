"""matplotlib through the ``plot`` extra, headless (Agg); drawing a figure that may fail, and writing a folder of
figures all at once."""
from __future__ import annotations

import os
import shutil
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path

from ..errors import InputError, ScenarioError


class PlotDependencyError(InputError):
    """matplotlib is missing: the ``plot`` extra is not installed."""


def require_matplotlib(option: str = "plot"):
    """matplotlib.pyplot on the Agg backend; a one-line error naming ``option`` when the extra is missing."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise PlotDependencyError(f"{option}: needs matplotlib: pip install 'simkit[plot]' (the plot extra)") from None
    return plt


def image_format(path, option: str = "--plot") -> str:
    """The image type of ``path`` from its extension ("png", "pdf", ...), checked against what matplotlib can
    write, before any work: a missing matplotlib or an unknown type is one error naming ``option``."""
    plt = require_matplotlib(option)
    kinds = plt.figure().canvas.get_supported_filetypes()
    plt.close("all")
    kind = Path(path).suffix.lower().lstrip(".")
    if kind not in kinds:
        raise ScenarioError(option, f"{path}: unknown image format {kind!r}: expected a file name ending in "
                                    f"{', '.join('.' + k for k in sorted(kinds))}")
    return kind


def save(fig, path) -> None:
    """Write ``fig`` as PNG and release it."""
    plt = require_matplotlib()
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def skip_line(message: str) -> None:
    """The default report of a figure left out: one line on stderr."""
    print(message, file=sys.stderr)


def draw(plt, path, make, *args, on_skip=skip_line) -> Path | None:
    """``make(plt, *args)`` saved as the PNG ``path``; None when it has nothing to draw (``make`` returned None)
    or failed, the failure reported as one line to ``on_skip`` (a figure is an extra: the others still come)."""
    try:
        fig = make(plt, *args)
        if fig is None:
            return None
        save(fig, path)
    except Exception as exc:  # noqa: BLE001 - any drawing failure skips that figure only, never a traceback
        plt.close("all")
        on_skip(f"plot: skipped {Path(path).name}: {type(exc).__name__}: {exc}")
        return None
    return Path(path)


@contextmanager
def staged_directory(out):
    """A new temporary directory beside ``out`` to write into; when the block succeeds its files move into
    ``out`` (created when missing; files of the same name replaced, others kept), when it fails it is removed,
    so a failure never leaves a half-written ``out``."""
    out = Path(out)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.tmp-", dir=out.parent))
    try:
        yield tmp
        if out.exists():
            _merge(tmp, out)
        else:
            tmp.rename(out)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _merge(src: Path, dst: Path) -> None:
    for item in src.iterdir():
        target = dst / item.name
        if item.is_dir():
            target.mkdir(exist_ok=True)
            _merge(item, target)
        else:
            os.replace(item, target)
