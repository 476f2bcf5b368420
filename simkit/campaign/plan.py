"""What a campaign runs: grid points (``--grid key=v1,v2``, the dotted keys of ``--set``) times seeds.

Run ``i`` of grid point ``p`` uses seed ``first_seed + i`` and the overrides of ``p``; its identity is checked
by content (the effective scenario text and the seed stored in the file), the file name is only a place.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass
from pathlib import Path

from ..errors import ScenarioError
from ..scenario import load, resolve
from .errors import CampaignInputError


@dataclass(frozen=True)
class RunSpec:
    """One run: ``run_id`` (file stem), the scenario (absolute path or bundled name), ``seed``, the grid point's
    ``overrides`` (tuple of 'key=value', TOML literals) and its index ``point``."""

    run_id: str
    scenario: str
    seed: int
    overrides: tuple[str, ...]
    point: int


def split_values(text: str) -> list[str]:
    """Split 'v1,v2,...' at top-level commas (not inside [], {} or quotes), so arrays stay whole."""
    items, depth, quote, cur = [], 0, "", []
    for ch in text:
        if quote:
            quote = "" if ch == quote else quote
        elif ch in "\"'":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == "," and depth == 0:
            items.append("".join(cur).strip())
            cur = []
            continue
        cur.append(ch)
    items.append("".join(cur).strip())
    return items


def parse_grid(specs) -> list[tuple[str, list[str]]]:
    """``["key=v1,v2", ...]`` -> [(key, [v1, v2]), ...], in order; one clear error per malformed item."""
    grid = []
    for spec in specs or ():
        key, sep, values = spec.partition("=")
        key = key.strip()
        if not sep or not key or not values.strip():
            raise CampaignInputError("--grid", f"expected dotted.key=v1,v2,..., got {spec!r}")
        items = split_values(values)
        if any(v == "" for v in items):
            raise CampaignInputError("--grid", f"{key}: empty value in {values!r}")
        if key in (k for k, _ in grid):
            raise CampaignInputError("--grid", f"{key} given twice")
        grid.append((key, items))
    return grid


def grid_points(grid) -> list[tuple[str, ...]]:
    """The cartesian product of the grid as override tuples (one empty tuple without a grid)."""
    keys = [k for k, _ in grid]
    return [tuple(f"{k}={v}" for k, v in zip(keys, combo)) for combo in itertools.product(*(v for _, v in grid))]


def scenario_reference(scenario) -> str:
    """The scenario as every worker will load it: an absolute path for a file, else the bundled name."""
    try:
        path = resolve(scenario)
    except ScenarioError as exc:
        raise CampaignInputError("SCENARIO", str(exc)) from None
    given = Path(str(scenario))
    return str(path.resolve()) if given.exists() else str(scenario)


def plan(scenario, runs: int, grid=None, first_seed: int = 0, overrides=()) -> list[RunSpec]:
    """Every run of the campaign; each grid point is loaded once here so that a bad key fails before any run."""
    if isinstance(runs, bool) or not isinstance(runs, int) or runs < 1:
        raise CampaignInputError("--runs", f"expected a positive integer, got {runs!r}")
    if isinstance(first_seed, bool) or not isinstance(first_seed, int) or first_seed < 0:
        raise CampaignInputError("--first-seed", f"expected a non-negative integer, got {first_seed!r}")
    ref = scenario_reference(scenario)
    specs = []
    for p, point in enumerate(grid_points(parse_grid(grid))):
        over = tuple(overrides) + point
        try:
            load(ref, list(over), seed=first_seed)
        except ScenarioError as exc:
            raise CampaignInputError("--grid" if point else "--set", str(exc)) from None
        specs += [RunSpec(f"p{p:03d}_s{first_seed + i:06d}", ref, first_seed + i, over, p) for i in range(runs)]
    return specs


def expected_text(spec: RunSpec) -> str:
    """The effective scenario text the file of ``spec`` must carry (root attribute ``scenario_toml``)."""
    return load(spec.scenario, list(spec.overrides), seed=spec.seed).text
