"""Built environment around the trajectory: buildings, street canyons and the vehicle's own body, and the
line-of-sight state each antenna has to each satellite (see docs/urban.md)."""
from .config import EnvironmentConfig, check_antennas, parse_config
from .los import (BELOW_HORIZON, BLOCKED, DIRECT, DIRECT_REFLECTED, NLOS, STATE_NAMES, Environment,
                  LineOfSight)
from .walls import Walls, canyon_walls, footprint_walls

__all__ = ["EnvironmentConfig", "check_antennas", "parse_config", "Environment", "LineOfSight", "Walls",
           "canyon_walls", "footprint_walls", "DIRECT", "DIRECT_REFLECTED", "NLOS", "BLOCKED", "BELOW_HORIZON",
           "STATE_NAMES"]
