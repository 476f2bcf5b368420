"""Multi-antenna carrier-phase attitude from a simkit file: DD float solution, ambiguity resolution (LAMBDA,
C-LAMBDA, MC-LAMBDA) with validation, attitude from the fixed baselines with covariance, and TDCP velocity.

``SOLVERS``: name -> ``callable(ds, params, progress) -> simkit.solution.Solution`` for ``simkit solve``.
See docs/attitude.md.
"""
from .dd import FloatGroup, Observations, float_solution
from .errors import AttitudeInputError
from .resolve import METHODS, FixPolicy, Resolution, resolve
from .solvers import build_registry
from .tight import FixedDD, fixed_dd, read_fixed_dd
from .velocity import solve_tdcp
from .wahba import badshah_eq10, euler_atdop, euler_covariance, phi_covariance, single_baseline, wahba_svd

SOLVERS = {**build_registry(), "tdcp": solve_tdcp}

__all__ = ["AttitudeInputError", "FixPolicy", "FixedDD", "FloatGroup", "METHODS", "Observations", "Resolution", "SOLVERS",
           "badshah_eq10", "euler_atdop", "euler_covariance", "fixed_dd", "float_solution", "phi_covariance",
           "read_fixed_dd", "resolve", "single_baseline", "wahba_svd"]
