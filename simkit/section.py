"""Typed reading of one scenario table, with errors that name the dotted key path.

Each stage parses its own section with a :class:`Section`: ``get`` takes a key with its expected type, default
and range check; ``done`` rejects any key nobody asked for. Errors are :class:`simkit.errors.ScenarioError`
(the loader adds the file name).
"""
from __future__ import annotations

import math
from typing import Any, Callable

from .errors import ScenarioError

REQUIRED = object()

_TYPE_NAMES = {float: "a number", int: "an integer", str: "a string", bool: "true or false", list: "an array"}


def _type_ok(value, kind) -> bool:
    if kind is float:
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if kind is int:
        return isinstance(value, int) and not isinstance(value, bool)
    return isinstance(value, kind)


class Section:
    """A view of one TOML table at dotted path ``path`` (``""`` for the root)."""

    def __init__(self, data: dict | None, path: str = ""):
        if data is not None and not isinstance(data, dict):
            raise ScenarioError(path, f"must be a table, got {type(data).__name__}")
        self.data = data or {}
        self.path = path
        self._seen: set[str] = set()

    def key(self, name: str) -> str:
        return f"{self.path}.{name}" if self.path else name

    def error(self, name: str, message: str) -> ScenarioError:
        return ScenarioError(self.key(name), message)

    def has(self, name: str) -> bool:
        return name in self.data

    def get(self, name: str, kind=float, default: Any = REQUIRED, check: Callable | None = None,
            choices=None, shape: int | None = None) -> Any:
        """The value of ``name``: of type ``kind`` (or a list of ``shape`` items of that type).

        ``check(value)`` returns an error text (e.g. "must be > 0") or None; ``choices`` lists allowed values.
        """
        self._seen.add(name)
        if name not in self.data:
            if default is REQUIRED:
                import difflib

                near = difflib.get_close_matches(name, [str(k) for k in self.data], n=1)
                hint = f"; found '{near[0]}': did you mean '{name}'?" if near else ""
                raise self.error(name, f"missing required key (expected {self._expect(kind, shape)}{hint})")
            return default
        value = self.data[name]
        if shape is not None:
            if not isinstance(value, list) or (shape > 0 and len(value) != shape) or not all(
                    _type_ok(v, kind) for v in value):
                raise self.error(name, f"expected {self._expect(kind, shape)}, got {value!r}")
            value = [float(v) if kind is float else v for v in value]
            if kind is float and not all(math.isfinite(v) for v in value):
                raise self.error(name, f"expected finite numbers, got {value!r}")
        else:
            if not _type_ok(value, kind):
                raise self.error(name, f"expected {self._expect(kind, shape)}, got {value!r}")
            if kind is float:
                value = float(value)
                if not math.isfinite(value):
                    raise self.error(name, f"expected a finite number, got {value!r}")
        if choices is not None and value not in choices:
            raise self.error(name, f"must be one of {', '.join(map(repr, choices))}, got {value!r}")
        if check is not None:
            problem = check(value)
            if problem:
                raise self.error(name, f"{problem}, got {value!r}")
        return value

    @staticmethod
    def _expect(kind, shape) -> str:
        if shape is None:
            return _TYPE_NAMES.get(kind, kind.__name__)
        n = f"{shape} " if shape else ""
        return f"an array of {n}{_TYPE_NAMES.get(kind, kind.__name__).split(' ', 1)[-1]}s"

    def section(self, name: str, required: bool = False) -> "Section":
        """The sub-table ``name`` (empty when absent and not required)."""
        self._seen.add(name)
        if name not in self.data:
            if required:
                raise self.error(name, "missing required table")
            return Section({}, self.key(name))
        return Section(self.data[name], self.key(name))

    def sections(self, name: str, required: bool = False) -> list["Section"]:
        """The array of tables ``[[name]]``, each with path ``name[i]``."""
        self._seen.add(name)
        items = self.data.get(name)
        if items is None:
            if required:
                raise self.error(name, "missing required array of tables")
            return []
        if isinstance(items, dict):
            items = [items]
        if not isinstance(items, list) or not all(isinstance(i, dict) for i in items):
            raise self.error(name, "expected an array of tables ([[...]])")
        return [Section(item, f"{self.key(name)}[{i}]") for i, item in enumerate(items)]

    def only(self, *names: str) -> None:
        """Reject, before anything is read, a key that is none of ``names``: a typo'd table is then named itself
        (with the nearest known name), not through the required keys it leaves missing elsewhere."""
        self._seen.update(names)
        self.done()

    def done(self) -> None:
        """Reject keys that were never read: a typo must not be silently ignored."""
        unknown = [k for k in self.data if k not in self._seen]
        if unknown:
            raise self.error(unknown[0], "unknown key" + self._suggest(unknown[0]))

    def _suggest(self, name: str) -> str:
        import difflib

        close = difflib.get_close_matches(name, sorted(self._seen), n=1)
        return f" (did you mean '{close[0]}'?)" if close else f" (known keys: {', '.join(sorted(self._seen))})"


def positive(v):
    return None if v > 0 else "must be > 0"


def non_negative(v):
    return None if v >= 0 else "must be >= 0"


def in_range(lo, hi):
    def check(v):
        return None if lo <= v <= hi else f"must be in [{lo}, {hi}]"

    return check
