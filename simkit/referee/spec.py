"""Pass/fail thresholds from a TOML spec.

```toml
[limits]                                   # upper limits on error statistics, units in the key names
horizontal = { rms_m = 2.0, p95_m = 4.0 }
velocity_3d = { rms_m_per_s = 0.05 }
heading = { rms_deg = 0.2, max_deg = 1.0 }

[convergence]                              # |error| <= threshold for good, reached within max_time_s
heading = { threshold_deg = 0.5, max_time_s = 60.0 }

[consistency]                              # chi-square tests, at confidence (default 0.95)
confidence = 0.95
nees_min_fraction_inside = 0.9             # fraction of epochs whose NEES lies inside the two-sided bounds
nis_min_fraction_inside = 0.9
```
Quantities and statistics are those of :mod:`simkit.referee.stats`. Without a spec no check is made and the
convergence thresholds are :data:`DEFAULT_CONVERGENCE`.
"""
from __future__ import annotations

import difflib
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from .errors import RefereeInputError
from .stats import STATS, UNIT_OF

DEFAULT_CONVERGENCE = {"horizontal": 1.0, "up": 2.0, "velocity_3d": 0.1, "heading": 0.5}
CONSISTENCY_KEYS = ("confidence", "nees_min_fraction_inside", "nis_min_fraction_inside")


@dataclass(frozen=True)
class Spec:
    """``limits`` {(quantity, stat): upper limit}; ``convergence`` {quantity: (threshold, max_time_s or None)};
    ``consistency`` {key: value}; limits in the units of ``stats.UNIT_OF`` (attitude in degrees)."""

    limits: dict = field(default_factory=dict)
    convergence: dict = field(default_factory=lambda: {q: (v, None) for q, v in DEFAULT_CONVERGENCE.items()})
    consistency: dict = field(default_factory=lambda: {"confidence": 0.95})


def _hint(key, known) -> str:
    close = difflib.get_close_matches(key, list(known), n=1)
    return f" (did you mean {close[0]!r}?)" if close else f" (one of {', '.join(sorted(known))})"


def _number(where, key, value, positive=True):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or (positive and not value > 0):
        raise RefereeInputError(where, f"{key}: expected a {'positive ' if positive else ''}number, got {value!r}")
    return float(value)


def _quantity_table(where, section, name, table):
    if name not in UNIT_OF:
        raise RefereeInputError(where, f"{section}.{name}: unknown quantity{_hint(name, UNIT_OF)}")
    if not isinstance(table, dict):
        raise RefereeInputError(where, f"{section}.{name}: expected a table like {{ rms_{UNIT_OF[name]} = 1.0 }}")
    return UNIT_OF[name]


def parse_spec(data: dict, where="spec") -> Spec:
    """A :class:`Spec` from the parsed TOML ``data``; unknown sections, quantities or keys are errors."""
    sections = ("limits", "convergence", "consistency")
    for section in data:
        if section not in sections:
            raise RefereeInputError(where, f"unknown section [{section}]{_hint(section, sections)}")
    limits, conv = {}, {}
    for name, table in data.get("limits", {}).items():
        unit = _quantity_table(where, "limits", name, table)
        keys = {f"{s}_{unit}": s for s in STATS}
        for key, value in table.items():
            if key not in keys:
                raise RefereeInputError(where, f"limits.{name}.{key}: unknown statistic{_hint(key, keys)}")
            limits[(name, keys[key])] = _number(where, f"limits.{name}.{key}", value)
    for name, table in data.get("convergence", {}).items():
        unit = _quantity_table(where, "convergence", name, table)
        known = (f"threshold_{unit}", "max_time_s")
        for key in table:
            if key not in known:
                raise RefereeInputError(where, f"convergence.{name}.{key}: unknown key{_hint(key, known)}")
        if known[0] not in table:
            raise RefereeInputError(where, f"convergence.{name}: missing {known[0]}")
        limit = table.get("max_time_s")
        conv[name] = (_number(where, f"convergence.{name}.{known[0]}", table[known[0]]),
                      None if limit is None else _number(where, f"convergence.{name}.max_time_s", limit, False))
    consistency = {"confidence": 0.95}
    for key, value in data.get("consistency", {}).items():
        if key not in CONSISTENCY_KEYS:
            raise RefereeInputError(where, f"consistency.{key}: unknown key{_hint(key, CONSISTENCY_KEYS)}")
        consistency[key] = _number(where, f"consistency.{key}", value)
        if not consistency[key] <= 1:
            raise RefereeInputError(where, f"consistency.{key}: expected a number in (0, 1], got {value!r}")
    return Spec(limits, conv or {q: (v, None) for q, v in DEFAULT_CONVERGENCE.items()}, consistency)


def load_spec(path) -> Spec:
    """Read and check a TOML spec file."""
    path = Path(path)
    if not path.is_file():
        raise RefereeInputError(path, "no such spec file")
    try:
        data = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise RefereeInputError(path, f"not valid TOML: {exc}") from None
    return parse_spec(data, path)
