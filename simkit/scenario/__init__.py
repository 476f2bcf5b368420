"""Scenario files: TOML -> validated :class:`Scenario`, with ``--set`` overrides and key-path errors."""
from .loader import Scenario, apply_override, bundled_names, load, resolve

__all__ = ["Scenario", "apply_override", "bundled_names", "load", "resolve"]
