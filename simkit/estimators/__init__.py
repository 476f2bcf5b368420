"""Inertial estimators: strapdown mechanisation, loosely coupled Kalman (15 states, and Badshah's lever-arm and
attitude variant) and H-infinity filters, code/Doppler single-point positioning. Arrays in, arrays out.

``SOLVERS`` maps ``simkit solve --filter`` names to callables ``(ds, params, progress) -> Solution``.
"""
from .align import motion_alignment, static_alignment
from .errors import EstimatorInputError
from .filters import FilterConfig, HInfinityFilter, KalmanFilter15, KalmanFilter15DD, KalmanFilter21, STATE_NAMES
from .inputs import AttitudeFixes, DDCarrier, GnssFixes, ImuData, InitialState
from .kalman import Correction, kalman_update
from .registry import DEFAULTS, SOLVERS
from ..gnss.spp import SppFixes, spp
from .strapdown import strapdown

__all__ = ["AttitudeFixes", "Correction", "DDCarrier", "DEFAULTS", "EstimatorInputError", "FilterConfig",
           "GnssFixes", "HInfinityFilter", "ImuData", "InitialState", "KalmanFilter15", "KalmanFilter15DD",
           "KalmanFilter21", "SOLVERS",
           "STATE_NAMES", "SppFixes", "kalman_update", "motion_alignment", "spp", "static_alignment", "strapdown"]
