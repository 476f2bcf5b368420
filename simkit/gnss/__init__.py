"""GNSS observables per antenna: code, carrier (true integer ambiguities), Doppler, C/N0, LLI, every error term.

Pipeline contract (docs/gnss.md)::

    cfg = parse_config(section)                       # the [gnss] table
    sim = GnssSimulator(cfg, start_week, start_sow, seed, duration_s)
    sim.epoch_times(); sim.static_datasets(); sim.process(t, pos_ecef, vel_ecef, quat_nb, omega_ib_b)
"""
from .config import GnssConfig, parse_config
from .differencing import (dd_covariance, dd_operator, double_difference, reference_satellites,
                           single_difference)
from .simulator import GnssSimulator

__all__ = ["parse_config", "GnssConfig", "GnssSimulator", "single_difference", "double_difference",
           "reference_satellites", "dd_operator", "dd_covariance"]
