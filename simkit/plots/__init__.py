"""Figures (matplotlib, the ``plot`` extra, Agg backend): a score's errors with +-3 sigma bounds, and the
overview of a simkit file (``simkit plot``): trajectory map and altitude, sky plot, visible satellites and DOPs,
IMU Allan deviation, observation errors, solutions against truth. Every figure is a PNG; units on every axis.
"""
from .common import require_matplotlib, staged_directory
from .file_figures import FIGURES, file_figures
from .score_figures import score_figures

__all__ = ["FIGURES", "file_figures", "require_matplotlib", "score_figures", "staged_directory"]
