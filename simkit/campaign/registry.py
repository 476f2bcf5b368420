"""The metric registry: name -> callable(ds: simkit.io.Dataset) -> dict of numbers.

A metric returns a flat dict of numbers (None or NaN where undefined) and an empty dict when the file lacks what
it needs. Counts named ``<x>_successes`` and ``<x>_trials`` are pooled by the campaign into a success rate with a
Wilson interval; every other number gets mean, spread and a Student-t interval over the runs. Later packages add
theirs with ``@register("nees")`` in a module that :mod:`simkit.campaign.metrics` imports, or a campaign names
them as ``package.module:function`` (imported on the worker).
"""
from __future__ import annotations

from collections.abc import Callable

Metric = Callable[..., dict]
REGISTRY: dict[str, Metric] = {}


def register(name: str, fn: Metric | None = None):
    """Register ``fn`` as metric ``name`` (usable as a decorator); a name is registered once."""
    def add(f):
        if name in REGISTRY and REGISTRY[name] is not f:
            raise ValueError(f"metric {name!r} is already registered")
        REGISTRY[name] = f
        return f
    return add(fn) if fn is not None else add
