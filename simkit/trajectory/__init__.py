"""High-dynamic trajectories with exact truth: segments -> smooth commands -> integrated, consistent truth."""
from .config import TrajectoryConfig, parse_config
from .generator import Trajectory, TrajectoryTruth
from .segments import KINDS

__all__ = ["Trajectory", "TrajectoryConfig", "TrajectoryTruth", "parse_config", "KINDS"]
