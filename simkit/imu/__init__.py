"""IMU simulation with coloured noise, sensor presets and Allan-variance analysis.

``parse_config(section)`` reads the scenario's [imu] table, ``ImuSimulator(cfg, rate_hz, seed).process(...)``
turns truth into measurements block by block, ``presets()`` lists the bundled sensor models, and
:mod:`simkit.imu.allan` computes and fits Allan deviations. See docs/imu.md.
"""
from .config import ImuConfig, SensorSpec, parse_config, presets
from .simulator import ImuBlock, ImuSimulator, truth_increments

__all__ = ["ImuBlock", "ImuConfig", "ImuSimulator", "SensorSpec", "parse_config", "presets", "truth_increments"]
