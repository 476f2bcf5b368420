"""Loading a scenario: TOML (tomllib) or a dict, ``--set`` overrides, validation into one :class:`Scenario`.

The top-level tables are ``[scenario]``, ``[trajectory]``, ``[imu]``, ``[gnss]`` and ``[environment]``; each
stage validates its own table. Every error is a :class:`ScenarioError` naming the file and the dotted key path.
"""
from __future__ import annotations

import copy
import re
import tomllib
from dataclasses import dataclass, field, replace
from datetime import datetime
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import tomli_w

from .. import gpstime
from ..errors import DataFileError, ScenarioError
from ..params import parse_value
from ..imu.config import ImuConfig, parse_config as parse_imu
from ..section import Section, positive
from ..trajectory import TrajectoryConfig, parse_config as parse_trajectory

if TYPE_CHECKING:
    from ..environment import EnvironmentConfig
    from ..gnss import GnssConfig

_INDEX = re.compile(r"^([A-Za-z_][\w-]*)(?:\[(\d+)\])?$")


def bundled_dir() -> Path:
    """The folder of scenarios shipped inside the package."""
    return Path(str(resources.files("simkit") / "scenarios"))


def bundled_names() -> list[str]:
    return sorted(p.stem for p in bundled_dir().glob("*.toml"))


def resolve(path_or_name: str | Path) -> Path:
    """A scenario file path, or the bundled scenario of that name (``quickstart`` or ``quickstart.toml``)."""
    p = Path(path_or_name)
    if p.is_file():
        return p
    if p.is_dir():
        raise ScenarioError("", "is a directory, expected a scenario TOML file", str(p))
    candidate = bundled_dir() / (p.name if p.suffix == ".toml" else p.name + ".toml")
    if candidate.is_file() and (len(p.parts) == 1 or p.parent.name == "scenarios"):
        return candidate
    raise ScenarioError("", f"no such scenario file (bundled scenarios: {', '.join(bundled_names())})", str(p))


@dataclass(frozen=True)
class Scenario:
    """A validated scenario. Times: ``start_week``/``start_sow`` in GPS time; ``duration_s`` in seconds.
    ``text`` is the effective scenario TOML, ``source`` where it came from, ``data`` the parsed table."""

    name: str
    description: str
    start: datetime
    start_week: int
    start_sow: float
    duration_s: float
    seed: int
    trajectory: TrajectoryConfig
    imu: ImuConfig | None = None
    gnss: GnssConfig | None = None
    environment: EnvironmentConfig | None = None
    text: str = ""
    source: str = ""
    data: dict = field(default_factory=dict)
    overrides: tuple = ()
    inputs: tuple = ()      # the files a run reads besides the scenario (log, buildings, navigation): never an output


def apply_override(data: dict, assignment: str) -> None:
    """Apply ``dotted.key[i].path=value`` to the scenario dict in place."""
    if "=" not in assignment:
        raise ScenarioError("--set", f"expected dotted.key=value, got {assignment!r}")
    key, text = assignment.split("=", 1)
    parts = key.strip().split(".")
    node: Any = data
    for depth, part in enumerate(parts):
        m = _INDEX.match(part)
        if not m:
            raise ScenarioError(key, f"--set: malformed key part {part!r}")
        name, index = m.group(1), m.group(2)
        last = depth == len(parts) - 1
        if index is not None:
            items = node.get(name)
            if not isinstance(items, list) or int(index) >= len(items):
                n = len(items) if isinstance(items, list) else 0
                raise ScenarioError(key, f"--set: {name} has {n} entries, no index {index}")
            if last:
                items[int(index)] = parse_value(text)
            node = items[int(index)]
        elif last:
            node[name] = parse_value(text)
        else:
            node = node.setdefault(name, {})
            if not isinstance(node, dict):
                raise ScenarioError(key, f"--set: {name} is not a table")


MAX_SEED = 2**64 - 1


def load(scenario: str | Path | dict, overrides: list[str] | None = None, seed: int | None = None) -> Scenario:
    """Read, override and validate a scenario (a TOML path, a bundled name, or a dict).

    ``seed`` (``--seed``) is the override ``scenario.seed``. ``Scenario.text`` is the effective scenario: the
    file's own text when nothing was overridden, else the overridden table written with ``tomli_w`` (running
    that text reproduces the run exactly).
    """
    overrides = list(overrides or [])
    if seed is not None:
        if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED:
            raise ScenarioError("--seed", f"expected an integer in [0, 2^64 - 1], got {seed!r}")
        overrides.append(f"scenario.seed={seed}")
    base_dir = None
    if isinstance(scenario, dict):
        data, text, source = copy.deepcopy(scenario), None, "<dict>"
    else:
        path = resolve(scenario)
        source, base_dir = str(scenario), path.parent
        try:
            if path.read_bytes()[:8] == b"\x89HDF\r\n\x1a\n":  # the HDF5 signature: a simulated file, not a scenario
                raise ScenarioError("", "is an HDF5 file (a simulated one?), expected a scenario TOML file", source)
            text = path.read_text(encoding="utf-8")
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise ScenarioError("", f"not valid TOML: {exc}", source) from None
        except (OSError, UnicodeDecodeError) as exc:
            raise ScenarioError("", f"cannot read: {exc}", source) from None
    try:
        for item in overrides:
            apply_override(data, item)
        sc = _validate(data, base_dir)
    except ScenarioError as exc:
        raise exc.with_source(source) from None
    if text is None or overrides:
        header = f"# effective scenario: {source}" + "".join(f"\n# --set {o}" for o in overrides)
        text = header + "\n" + tomli_w.dumps(data)
    return replace(sc, text=text, source=source, data=data, overrides=tuple(overrides))


def _validate(data: dict, base_dir: Path | None = None) -> Scenario:
    root = Section(data, "")
    root.only("scenario", "trajectory", "imu", "gnss", "environment")
    meta = root.section("scenario", required=True)
    name = meta.get("name", str, check=lambda v: None if re.fullmatch(r"[\w.-]+", v) else
                    "must be letters, digits, '_', '-' or '.'")
    description = meta.get("description", str, "")
    start_text = meta.get("start", str)
    try:
        start = gpstime.parse_utc(start_text)
    except ValueError:
        raise meta.error("start", f"expected a UTC ISO 8601 time like 2016-11-08T00:00:00Z, got {start_text!r}")
    duration = meta.get("duration_s", float, check=positive)
    seed = meta.get("seed", int, 0, check=lambda v: None if 0 <= v <= MAX_SEED else "must be in [0, 2^64 - 1]")
    meta.done()
    week, sow = gpstime.utc_to_gps(start)

    traj = parse_trajectory(root.section("trajectory", required=True))
    if traj.log is not None:   # a logged trajectory: read and fitted now, so a bad log is reported at load
        from ..logs import fit_trajectory

        traj = fit_trajectory(traj, base_dir, start, week, sow, duration)
    imu = gnss = None
    if root.has("imu"):
        imu = parse_imu(root.section("imu"))
        rate = getattr(imu, "rate_hz", None)
        if rate is not None and abs(rate - traj.rate_hz) > 1e-9:
            raise ScenarioError("imu.rate_hz", f"must equal trajectory.rate_hz ({traj.rate_hz:g}): the truth is "
                                f"generated at the IMU rate, got {rate:g}")
    if root.has("gnss"):
        from ..gnss import parse_config as parse_gnss  # here: the GNSS stage's imports cost a truth + IMU run 0.5 s

        gnss = parse_gnss(root.section("gnss"))
        ratio = traj.rate_hz / gnss.rate_hz
        if abs(ratio - round(ratio)) > 1e-9 or round(ratio) < 1:
            raise ScenarioError("gnss.rate_hz", f"must divide trajectory.rate_hz ({traj.rate_hz:g}) into a whole "
                                f"number of samples, got {gnss.rate_hz:g}")
    env = None
    if root.has("environment"):
        if gnss is None:
            raise ScenarioError("environment", "needs a [gnss] section: the environment acts on its signals")
        from ..environment import check_antennas, parse_config as parse_environment

        env = parse_environment(root.section("environment"), (traj.lat_rad, traj.lon_rad, traj.height_m), base_dir)
        check_antennas(env, np.array([a.lever_arm_b for a in gnss.antennas]))
    root.done()
    return Scenario(name=name, description=description, start=start, start_week=week, start_sow=sow,
                    duration_s=duration, seed=seed, trajectory=traj, imu=imu, gnss=gnss, environment=env,
                    inputs=_input_files(traj, gnss, env, base_dir))


def _input_files(traj, gnss, env, base_dir) -> tuple[Path, ...]:
    """The files the scenario reads: its trajectory log and buildings (checked above, so they exist) and its
    constellation files (bundled ones included; a missing one is reported by the constellation stage)."""
    files = []
    if traj.log is not None:
        from ..logs import log_path

        files.append(log_path(traj.log.source, base_dir))
    if env is not None and env.buildings is not None:
        from ..environment.config import find_file

        files.append(find_file(env.buildings, base_dir))
    if gnss is not None:
        from ..constellation.sources import resolve

        for source in gnss.sources:
            name = source.split(":", 1)[1] if source.startswith("almanac:") else source
            try:
                files.append(None if name.startswith("nominal:") else resolve(name))
            except DataFileError:
                pass
    return tuple(f for f in files if f is not None)
