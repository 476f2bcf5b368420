"""matplotlib through the ``plot`` extra, headless (Agg)."""
from __future__ import annotations

from ..errors import SimkitError


class PlotDependencyError(SimkitError):
    """matplotlib is missing: the ``plot`` extra is not installed."""

    exit_code = 2


def require_matplotlib(option: str = "plot"):
    """matplotlib.pyplot on the Agg backend; a one-line error naming ``option`` when the extra is missing."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise PlotDependencyError(f"{option}: needs matplotlib: pip install 'simkit[plot]' (the plot extra)") from None
    return plt


def save(fig, path) -> None:
    """Write ``fig`` as PNG and release it."""
    plt = require_matplotlib()
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
