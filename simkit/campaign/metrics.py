"""Per-run metrics: look-up and evaluation over the registry (:mod:`.registry`), and the built-in metrics.

Built in: ``imu_errors`` and ``gnss_errors`` (:mod:`.builtin`), ``ambiguity`` (:mod:`.ambiguity_metric`).
"""
from __future__ import annotations

import importlib

import numpy as np

from . import ambiguity_metric, builtin  # noqa: F401 - they register the built-in metrics
from .errors import CampaignInputError
from .registry import REGISTRY, Metric, register

DEFAULT_METRICS = ("imu_errors", "gnss_errors", "ambiguity")

__all__ = ["DEFAULT_METRICS", "evaluate", "get", "names", "register"]


def names() -> list[str]:
    """The registered metric names."""
    return sorted(REGISTRY)


def get(name: str) -> Metric:
    """The metric ``name``: a registered name or ``package.module:function``."""
    if name in REGISTRY:
        return REGISTRY[name]
    module, sep, attr = name.partition(":")
    if sep and module and attr:
        try:
            fn = getattr(importlib.import_module(module), attr)
        except (ImportError, AttributeError) as exc:
            raise CampaignInputError("--metric", f"{name}: cannot import ({exc})") from None
        if callable(fn):
            return fn
    raise CampaignInputError("--metric", f"unknown metric {name!r}; expected one of {', '.join(names())} "
                             "or package.module:function")


def evaluate(ds, metric_names) -> dict[str, dict]:
    """Every metric of ``metric_names`` on the open file ``ds``: {metric name: {key: number}}."""
    return {name: _clean(get(name)(ds)) for name in metric_names}


def _clean(values: dict) -> dict:
    """Numbers as plain floats/ints, NaN and inf as None (JSON has neither)."""
    out = {}
    for key, v in values.items():
        v = v.item() if hasattr(v, "item") else v
        if isinstance(v, float) and not np.isfinite(v):
            v = None
        out[str(key)] = v
    return out
