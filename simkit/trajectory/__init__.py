"""High-dynamic trajectories with exact truth: segments -> smooth commands -> integrated, consistent truth."""
from .config import TrajectoryConfig, parse_config
from .generator import Trajectory, Truth
from .segments import KINDS

__all__ = ["Trajectory", "TrajectoryConfig", "Truth", "parse_config", "KINDS"]
