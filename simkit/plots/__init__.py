"""Figures (matplotlib, the ``plot`` extra, Agg backend): a score's errors with +-3 sigma bounds, and the
overview of a simkit file (``simkit plot``): trajectory map and altitude, sky plot, visible satellites and DOPs,
IMU Allan deviation, observation errors, solutions against truth; and the figures of ``simkit allan --plot``,
``simkit sky --plot`` and ``simkit validate --report``. Every figure has units on every axis. The only
sub-package that imports matplotlib.
"""
from .command_figures import allan_figure, sky_figure, validation_figures
from .common import image_format, require_matplotlib, staged_directory
from .file_figures import FIGURES, file_figures
from .score_figures import score_figures
from .twin_figures import twin_figures

__all__ = ["FIGURES", "allan_figure", "file_figures", "image_format", "require_matplotlib", "score_figures",
           "sky_figure", "staged_directory", "twin_figures", "validation_figures"]
