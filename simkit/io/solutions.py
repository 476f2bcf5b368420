"""``/solutions/<name>/``: writing and reading estimator outputs (:class:`simkit.solution.Solution`).

A re-solve replaces only its own group: the new group is written under a temporary name in the same file and
moved into place once complete, so an interrupted solve leaves the previous solution (and everything else)
untouched. HDF5 does not reclaim the space of a replaced group; ``h5repack`` does.

Group attributes: ``config`` (JSON) and ``point`` (the point the position and velocity belong to, see
:mod:`simkit.solution`; a group without it, written before it existed, is read as "imu").
"""
from __future__ import annotations

import json
import os
import re

import h5py
import numpy as np

from ..errors import DataFileError
from ..solution import Solution, parse_point
from . import schema
from .dataset import open_dataset

_NAME = re.compile(r"^[A-Za-z0-9_.-]+$")
_FIELDS = ("t", "pos_ecef", "vel_enu", "quat_nb", "euler", "cov")


def write_solution(path, name: str, sol: Solution) -> None:
    """Store ``sol`` as ``/solutions/<name>`` in the simkit file ``path`` (replacing a previous one)."""
    if not _NAME.match(name):
        raise ValueError(f"solution name: expected letters, digits, '_', '-' or '.', got {name!r}")
    open_dataset(path).close()  # a simkit file of this schema, or a clear error
    with h5py.File(path, "r+") as f:
        root = f.require_group("solutions")
        tmp = f".{name}.tmp-{os.getpid()}"
        if tmp in root:
            del root[tmp]
        g = root.create_group(tmp)
        try:
            _fill(g, name, sol)
        except BaseException:
            del root[tmp]
            raise
        if name in root:
            del root[name]
        root.move(tmp, name)


def _fill(g: h5py.Group, name: str, sol: Solution) -> None:
    g.attrs["config"] = json.dumps(sol.config)
    g.attrs["point"] = sol.point
    for key in _FIELDS:
        value = getattr(sol, key)
        if value is not None:
            _dataset(g, f"solutions/{name}/{key}", key, np.asarray(value, dtype=float))
    if sol.state_names:
        _dataset(g, f"solutions/{name}/state_names", "state_names",
                 np.array(sol.state_names, dtype=h5py.string_dtype()))
    for key, value in sol.extras.items():
        ds = _dataset(g, f"solutions/{name}/extras/{key}", f"extras/{key}", np.asarray(value))
        ds.attrs["units"] = sol.extra_units.get(key, "")


def _dataset(g, path, key, data):
    spec = schema.check(path, data.dtype if data.dtype.kind != "O" else np.dtype("U1"), data.shape)
    options = dict(compression="gzip", compression_opts=1, shuffle=True) if data.ndim and data.size > 1024 else {}
    ds = g.create_dataset(key, data=data, **options)
    ds.attrs["units"] = spec.units
    if spec.frame:
        ds.attrs["frame"] = spec.frame
    return ds


def solution_names(path) -> list[str]:
    """Names of the solutions stored in the file."""
    with open_dataset(path) as ds:
        return sorted(n for n in ds.groups("solutions") if not n.startswith("."))


def read_solution(path, name: str) -> Solution:
    """The solution ``name`` of the file, as a :class:`Solution`."""
    with open_dataset(path) as ds:
        prefix = f"solutions/{name}"
        if f"{prefix}/t" not in ds:
            known = ", ".join(sorted(n for n in ds.groups("solutions") if not n.startswith("."))) or "none"
            raise DataFileError(path, f"no solution {name!r} (stored: {known})")
        values = {k: ds[f"{prefix}/{k}"][()] for k in _FIELDS if f"{prefix}/{k}" in ds}
        names = tuple(ds[f"{prefix}/state_names"][()]) if f"{prefix}/state_names" in ds else ()
        extras, units = {}, {}
        for key in ds.members(f"{prefix}/extras"):
            extras[key] = ds[f"{prefix}/extras/{key}"][()]
            units[key] = ds[f"{prefix}/extras/{key}"].units
        attrs = ds.group_attrs(prefix)
        config = json.loads(attrs.get("config", "{}"))
        point = str(attrs.get("point", "imu"))
    try:
        parse_point(point)
    except ValueError as exc:
        raise DataFileError(path, f"/solutions/{name} attribute {exc}") from None
    return Solution(state_names=tuple(str(n) for n in names), extras=extras, extra_units=units, config=config,
                    point=point, **values)
