"""IMU error-model configuration: scenario keys (units in their names) -> SI parameters, and the bundled presets.

Conventions (README, "Conventions"): noise densities are two-sided PSD (IEEE Std 952); ``bias_instability_*`` is the IEEE
coefficient B of flicker noise, whose Allan-deviation floor is ``sqrt(2 ln 2 / pi) B = 0.664 B`` (vendors usually
quote the floor itself: divide it by 0.664 to get B).
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import asdict, dataclass, field
from importlib import resources

from ..earth import G0  # standard gravity: the unit behind "g", "mg" and "ug" in datasheets
from ..errors import ScenarioError
from ..section import Section, non_negative, positive

DEG = math.pi / 180.0
HOUR = 3600.0
OUTPUTS = ("rates", "increments")
IDEAL = "ideal"


@dataclass(frozen=True)
class GaussMarkovConfig:
    """A first-order Gauss-Markov process: stationary 1-sigma ``sigma`` (SI) and correlation time ``tau_s``."""

    sigma: float
    tau_s: float


@dataclass(frozen=True)
class SensorSpec:
    """Error model of one sensor triad, SI units (gyro: rad, rad/s; accel: m/s, m/s^2).

    Random constants (turn-on bias, scale factor, misalignment, g-sensitivity) are 1-sigma values of a draw per run.
    """

    bias_turn_on: float = 0.0            # rad/s | m/s^2, 1-sigma per axis per run
    bias_instability: float = 0.0        # IEEE B, rad/s | m/s^2 (ADEV floor 0.664 B)
    bias_instability_tau_min_s: float = 0.1     # flicker band: shortest correlation time
    bias_instability_tau_max_s: float = 1.0e4   # flicker band: longest correlation time
    random_walk: float = 0.0             # N: ARW rad/sqrt(s) | VRW m/s/sqrt(s)  (two-sided PSD N^2)
    rate_random_walk: float = 0.0        # K: rad/s/sqrt(s) | m/s^2/sqrt(s)
    gauss_markov: tuple[GaussMarkovConfig, ...] = ()
    quantization: float = 0.0            # increment LSB: rad | m/s (IEEE Q = LSB / sqrt(12))
    scale_factor: float = 0.0            # 1-sigma, dimensionless (ppm * 1e-6)
    scale_factor_nonlinearity: float = 0.0   # error at full scale as a fraction of full scale
    misalignment: float = 0.0            # rad, 1-sigma of each of the 6 off-diagonal elements
    g_sensitivity: float = 0.0           # gyro only: rad/s per m/s^2, 1-sigma of each of the 9 elements
    range: float = 0.0                   # full scale, rad/s | m/s^2 (0: no saturation)
    bandwidth_hz: float = 0.0            # 2nd-order Butterworth -3 dB frequency (0: unlimited)
    vibration_psd: tuple[tuple[float, float], ...] = ()  # ONE-sided PSD table (Hz, (rad/s)^2/Hz | (m/s^2)^2/Hz)

    @property
    def is_ideal(self) -> bool:
        return self == SensorSpec(bias_instability_tau_min_s=self.bias_instability_tau_min_s,
                                  bias_instability_tau_max_s=self.bias_instability_tau_max_s)


@dataclass(frozen=True)
class ImuConfig:
    """The resolved [imu] table: preset name, optional explicit rate, output kind and the two sensor specs."""

    preset: str = IDEAL
    rate_hz: float | None = None
    output: str = "rates"
    gyro: SensorSpec = field(default_factory=SensorSpec)
    accel: SensorSpec = field(default_factory=SensorSpec)
    source: str = ""                     # citation of the preset's datasheet / paper

    def attributes(self) -> dict:
        """JSON-serialisable parameters in SI units."""
        out = asdict(self)
        for s in ("gyro", "accel"):
            out[s]["gauss_markov"] = [dict(g) for g in out[s]["gauss_markov"]]
        return out


# Scenario key -> (SensorSpec field, factor to SI), per sensor.  Units are in the key names (README, "Conventions").
_GYRO_KEYS = {
    "bias_turn_on_deg_per_h": ("bias_turn_on", DEG / HOUR),
    "bias_instability_deg_per_h": ("bias_instability", DEG / HOUR),
    "arw_deg_per_sqrt_h": ("random_walk", DEG / math.sqrt(HOUR)),
    "rrw_deg_per_h_per_sqrt_h": ("rate_random_walk", DEG / HOUR / math.sqrt(HOUR)),
    "quantization_urad": ("quantization", 1e-6),
    "scale_factor_ppm": ("scale_factor", 1e-6),
    "scale_factor_nonlinearity_ppm": ("scale_factor_nonlinearity", 1e-6),
    "misalignment_mrad": ("misalignment", 1e-3),
    "g_sensitivity_deg_per_h_per_g": ("g_sensitivity", DEG / HOUR / G0),
    "range_deg_per_s": ("range", DEG),
    "bandwidth_hz": ("bandwidth_hz", 1.0),
    "bias_instability_tau_min_s": ("bias_instability_tau_min_s", 1.0),
    "bias_instability_tau_max_s": ("bias_instability_tau_max_s", 1.0),
}
_ACCEL_KEYS = {
    "bias_turn_on_mg": ("bias_turn_on", 1e-3 * G0),
    "bias_instability_ug": ("bias_instability", 1e-6 * G0),
    "vrw_m_per_s_per_sqrt_h": ("random_walk", 1.0 / math.sqrt(HOUR)),
    "rrw_ug_per_sqrt_h": ("rate_random_walk", 1e-6 * G0 / math.sqrt(HOUR)),
    "quantization_mm_per_s": ("quantization", 1e-3),
    "scale_factor_ppm": ("scale_factor", 1e-6),
    "scale_factor_nonlinearity_ppm": ("scale_factor_nonlinearity", 1e-6),
    "misalignment_mrad": ("misalignment", 1e-3),
    "range_g": ("range", G0),
    "bandwidth_hz": ("bandwidth_hz", 1.0),
    "bias_instability_tau_min_s": ("bias_instability_tau_min_s", 1.0),
    "bias_instability_tau_max_s": ("bias_instability_tau_max_s", 1.0),
}
# [[imu.<sensor>.gauss_markov]] tables: sigma key and its factor to SI
_GM_SIGMA = {"gyro": ("sigma_deg_per_h", DEG / HOUR), "accel": ("sigma_ug", 1e-6 * G0)}
SENSOR_KEYS = {"gyro": _GYRO_KEYS, "accel": _ACCEL_KEYS}
# Vibration PSD table key (pairs [f_hz, one-sided psd]) and the factor of its PSD column to SI
VIBRATION_KEYS = {"gyro": ("vibration_psd_deg2_per_s2_per_hz", DEG * DEG),
                  "accel": ("vibration_psd_g2_per_hz", G0 * G0)}


def presets() -> list[str]:
    """Names accepted by ``imu.preset``: "ideal" and the bundled preset files."""
    files = resources.files(__package__).joinpath("presets").iterdir()
    return [IDEAL] + sorted(f.name[:-5] for f in files if f.name.endswith(".toml"))


def preset_table(name: str) -> dict:
    """The raw table of preset ``name`` (same keys as a scenario's [imu] table, plus [preset] metadata)."""
    if name == IDEAL:
        return {}
    path = resources.files(__package__).joinpath("presets", f"{name}.toml")
    if not path.is_file():
        raise ScenarioError("imu.preset", f"unknown preset {name!r} (known: {', '.join(presets())})")
    with path.open("rb") as fh:
        return tomllib.load(fh)


def _merge(base: dict, over: dict) -> dict:
    out = dict(base)
    for k, v in over.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def _vibration_table(sec: Section, name: str) -> tuple[tuple[float, float], ...]:
    """The [[f_hz, psd], ...] table of ``name``'s vibration key, PSD in SI; checked pairs, f and PSD > 0, f rising."""
    key, factor = VIBRATION_KEYS[name]
    table = sec.get(key, list, [])
    if not table:
        return ()
    if len(table) < 2 or not all(isinstance(p, list) and len(p) == 2 and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in p) for p in table):
        raise sec.error(key, f"expected an array of at least 2 [f_hz, psd] pairs of finite numbers, got {table!r}")
    if not all(f > 0 and s > 0 for f, s in table):
        raise sec.error(key, f"frequencies and PSD values must be > 0, got {table!r}")
    if not all(a[0] < b[0] for a, b in zip(table, table[1:])):
        raise sec.error(key, f"frequencies must be strictly increasing, got {table!r}")
    return tuple((float(f), float(s) * factor) for f, s in table)


def _parse_sensor(sec: Section, name: str) -> SensorSpec:
    values = {}
    for key, (attr, factor) in SENSOR_KEYS[name].items():
        check = positive if attr.startswith("bias_instability_tau") else non_negative
        v = sec.get(key, float, None, check=check)
        if v is not None:
            values[attr] = v * factor
    sigma_key, factor = _GM_SIGMA[name]
    gms = []
    for gm in sec.sections("gauss_markov"):
        gms.append(GaussMarkovConfig(gm.get(sigma_key, float, check=non_negative) * factor,
                               gm.get("tau_s", float, check=positive)))
        gm.done()
    values["vibration_psd"] = _vibration_table(sec, name)
    sec.done()
    spec = SensorSpec(gauss_markov=tuple(gms), **values)
    if spec.bias_instability_tau_min_s >= spec.bias_instability_tau_max_s:
        raise sec.error("bias_instability_tau_max_s", "must be > bias_instability_tau_min_s")
    if spec.scale_factor_nonlinearity > 0 and spec.range <= 0:
        rng_key = "range_deg_per_s" if name == "gyro" else "range_g"
        raise sec.error("scale_factor_nonlinearity_ppm", f"needs {rng_key} (the full scale it refers to)")
    return spec


def parse_config(section: Section) -> ImuConfig:
    """Read the scenario's [imu] table (a :class:`Section` at path "imu") on top of its preset.

    Explicit keys override the preset's values (a ``gauss_markov`` array replaces the preset's whole array).
    Raises :class:`ScenarioError` naming the dotted key path for unknown keys, wrong types or ranges.
    """
    preset = section.get("preset", str, IDEAL)
    table = preset_table(preset)
    meta = table.pop("preset", {})
    rate = section.get("rate_hz", float, None, check=positive)
    output = section.get("output", str, table.get("output", "rates"), choices=OUTPUTS)
    merged = Section({s: _merge(table.get(s, {}), section.data.get(s, {})) for s in ("gyro", "accel")},
                     section.path)
    specs = {s: _parse_sensor(merged.section(s), s) for s in ("gyro", "accel")}
    for s in ("gyro", "accel"):
        section.section(s)  # mark as read: the merged copy above already checked its keys
    section.done()
    return ImuConfig(preset=preset, rate_hz=rate, output=output, source=meta.get("source", ""), **specs)
