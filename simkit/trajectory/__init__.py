"""High-dynamic trajectories with exact truth: segments -> smooth commands -> integrated, consistent truth."""
from .generator import Trajectory, TrajectoryConfig, Truth, parse_config
from .segments import KINDS

__all__ = ["Trajectory", "TrajectoryConfig", "Truth", "parse_config", "KINDS"]
