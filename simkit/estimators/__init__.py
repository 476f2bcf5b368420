"""Inertial estimators: strapdown mechanisation, loosely coupled Kalman (15/21 states) and H-infinity filters,
code/Doppler single-point positioning. Arrays in, arrays out; ``SOLVERS`` maps ``simkit solve --filter`` names
to callables ``(ds, params, progress) -> Solution``."""
from .errors import EstimatorInputError
from .strapdown import strapdown

__all__ = ["EstimatorInputError", "strapdown"]
