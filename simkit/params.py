"""One parameter schema for every solver of ``simkit solve`` (``--set estimator.<key>=<TOML literal>``).

The defaults stay where each package declares them (``simkit.estimators.registry.DEFAULTS``,
``simkit.attitude.params.AMBIGUITY_DEFAULTS`` / ``TDCP_DEFAULTS``); :data:`SCHEMA` adds, per key, the type, the
range or check, the choices and a one-line doc. :func:`merge` is the one checker both packages use: unknown keys,
wrong types and out-of-range values raise one line naming ``estimator.<key>``. Booleans are never numbers, and an
integer key refuses a float (1.5 or 2.0 for an antenna index). :func:`check_against_file` adds what depends on the
file (antenna index, antenna count a value needs), so ``simkit solve`` checks everything before any filter runs.
A key a package adds to its defaults without a schema entry is checked by the type of its default.
"""
from __future__ import annotations

import math
import numbers
import tomllib
from dataclasses import dataclass
from typing import Callable

from .errors import ScenarioError


@dataclass(frozen=True)
class Param:
    """One parameter: ``kind`` float, int, str or bool; ``shape`` n: a list of n values of ``kind``;
    ``check(value)`` -> None or what was expected ("expected ..."); ``choices``; ``optional``: None allowed
    (the value then comes from the file); ``infinite``: +-inf allowed (an open bound); ``needs_antennas``:
    {value: antennas the file must have for it}; ``antenna_index``: an index into the file's antennas."""

    kind: type
    doc: str
    check: Callable | None = None
    choices: tuple | None = None
    shape: int | None = None
    optional: bool = False
    infinite: bool = False
    needs_antennas: dict | None = None
    antenna_index: bool = False


def above(lo, unit=""):
    return lambda v: None if v > lo else f"expected a number > {lo:g}{unit}"


def at_least(lo, what="a number"):
    return lambda v: None if v >= lo else f"expected {what} >= {lo:g}"


def within(lo, hi, what="a number", open_lo=False, open_hi=False):
    """lo <= v <= hi (strict at an open end), else "expected <what> in [lo, hi]" with matching brackets."""
    def check(v):
        ok = (v > lo if open_lo else v >= lo) and (v < hi if open_hi else v <= hi)
        return None if ok else f"expected {what} in {'(' if open_lo else '['}{lo:g}, {hi:g}{')' if open_hi else ']'}"
    return check


def _list_check(inner):
    return lambda values: next((problem for problem in map(inner, values) if problem), None)


POS = above(0)
NONNEG = at_least(0)
FLAG = {"choices": (0, 1)}
MASK = within(-90, 90, "an elevation in deg")
_SIGNALS = "comma-separated signal names of the file, or 'all'"

SCHEMA: dict[str, Param] = {
    # simkit.estimators (registry.DEFAULTS)
    "gnss": Param(str, "GNSS input: single-point fixes ('spp') or the truth plus noise ('truth', a study input)",
                  choices=("spp", "truth")),
    "antenna": Param(int, "antenna whose observations or fixes are used (0 .. A-1)", NONNEG, antenna_index=True),
    "elevation_mask_deg": Param(float, "SPP elevation mask (deg)", MASK),
    "sigma_code_m": Param(float, "code noise (m, 1 sigma)", POS),
    "sigma_doppler_m_per_s": Param(float, "Doppler range-rate noise (m/s, 1 sigma)", POS),
    "ionosphere": Param(str, "ionosphere correction of SPP (iono-free: dual-frequency code combination)",
                        choices=("broadcast", "none", "iono-free")),
    "systems": Param(str, "SPP: the systems used, letters of G, C, E, R, J ('' : every system of the file)",
                     lambda v: None if set(v) <= set("GCERJ") and len(set(v)) == len(v) else
                     "expected distinct letters of G, C, E, R, J (e.g. 'GC'), or ''"),
    "clock": Param(str, "SPP receiver clocks: one per system, or one for all with the file's broadcast system-time "
                   "offsets (/gnss/time_offset) removed", choices=("per-system", "single")),
    "truth_pos_sigma_m": Param(float, "gnss=truth: position noise E, N, U (m)", _list_check(NONNEG), shape=3),
    "truth_vel_sigma_m_per_s": Param(float, "gnss=truth: velocity noise (m/s)", POS),
    "seed": Param(int, "seed of the study noise (gnss=truth, attitude_source=truth)", NONNEG),
    "align": Param(str, "initial alignment", choices=("auto", "static", "motion", "truth", "attitude"),
                   needs_antennas={"attitude": 3}),
    "align_static_s": Param(float, "static alignment span (s)", POS),
    "init_heading_error_deg": Param(float, "heading error added to the alignment (deg)"),
    "p0_att_deg": Param(float, "initial attitude sigma pitch, roll, heading (deg)", _list_check(NONNEG), shape=3),
    "p0_vel_m_per_s": Param(float, "initial velocity sigma (m/s)", POS),
    "p0_pos_m": Param(float, "initial position sigma E, N, U (m)", _list_check(NONNEG), shape=3),
    "gyro_arw": Param(float, "gyro white noise (rad/s/sqrt(Hz)); default from /imu", POS, optional=True),
    "accel_vrw": Param(float, "accelerometer white noise (m/s^2/sqrt(Hz)); default from /imu", POS, optional=True),
    "gyro_bias_rw": Param(float, "gyro bias random walk (rad/s^2/sqrt(Hz)); default from /imu", NONNEG,
                          optional=True),
    "accel_bias_rw": Param(float, "accelerometer bias random walk (m/s^3/sqrt(Hz)); default from /imu", NONNEG,
                           optional=True),
    "p0_gyro_bias": Param(float, "initial gyro bias sigma (rad/s); default from /imu", POS, optional=True),
    "p0_accel_bias": Param(float, "initial accelerometer bias sigma (m/s^2); default from /imu", POS,
                           optional=True),
    "cov_dt_s": Param(float, "interval of the stored covariance (s)", POS),
    "pos_sigma_scale": Param(float, "scale of the GNSS position covariance", POS),
    "gnss_error_sigma_m": Param(float, "sigma E, N, U of the GNSS fixes' slowly varying error, estimated as three "
                                "Gauss-Markov states (m; 0 0 0: none); default: 1.5 1.5 3 with gnss=spp, none "
                                "with gnss=truth and in hinf", _list_check(NONNEG), shape=3, optional=True),
    "gnss_error_tau_s": Param(float, "correlation time of that error (s)", POS),
    "alpha": Param(float, "H-infinity bound factor (Wu 2015 uses 10)", lambda v: None if v > 1 else
                   "expected > 1 (Wu 2015 uses 10)"),
    "gamma_rule": Param(str, "H-infinity gamma rule", choices=("wu", "weighted")),
    "use_attitude": Param(bool, "kf21: use the GNSS attitude as a measurement"),
    "attitude_sigma_deg": Param(float, "attitude_source=truth: attitude noise (deg)", POS),
    "p0_lever_m": Param(float, "kf21: initial lever-arm sigma (m)", POS),
    "lever_rate_window_s": Param(float, "kf21: body-rate window of the lever-arm rows (s; 0: the sample)", NONNEG),
    "lever_arm_error_m": Param(float, "kf21: error added to the file's lever arm, body x, y, z (m)", shape=3),
    "attitude_source": Param(str, "kf21: GNSS attitude from the solver, none, or the truth (a study input)",
                             choices=("auto", "attitude", "none", "truth"), needs_antennas={"attitude": 3}),
    "attitude_method": Param(str, "attitude solver for kf21 / align=attitude",
                             choices=("attitude", "attitude_c", "attitude_mc")),
    "dd_method": Param(str, "kf15_dd: ambiguity method", choices=("lambda", "clambda", "mclambda")),
    "dd_signals": Param(str, f"kf15_dd: signals, {_SIGNALS}"),
    "dd_mask_deg": Param(float, "kf15_dd: DD elevation mask (deg)", MASK),
    "dd_ratio_threshold": Param(float, "kf15_dd: ratio test threshold", POS),
    "dd_gate_p": Param(float, "kf15_dd: innovation gate false-alarm probability (0: off)",
                       within(0, 1, "a probability", open_hi=True)),
    "dd_correlation_s": Param(float, "kf15_dd: time correlation of the DD errors (s; 0: off)",
                              at_least(0, "a number (s; 0: off)")),
    "dd_correlation_window_s": Param(float, "kf15_dd: correlation window (s; 0: off)",
                                     at_least(0, "a number (s; 0: off)")),
    # simkit.attitude (params.AMBIGUITY_DEFAULTS, TDCP_DEFAULTS)
    "signals": Param(str, _SIGNALS),
    "mask_deg": Param(float, "elevation mask (deg)", MASK),
    "max_sats": Param(int, "satellites per epoch at most (0: all)", NONNEG),
    "validation": Param(str, "fix validation: pf (ratio test and the ILS failure rate held at pf), ratio, ffrt, none",
                        choices=("pf", "ratio", "ffrt", "none")),
    "ratio_threshold": Param(float, "ratio test threshold (0: accept every search)", NONNEG),
    "pf": Param(float, "pf and ffrt: tolerated failure rate per epoch", within(0, 1, "a probability", True, True)),
    "ffrt_samples": Param(int, "ffrt: Monte Carlo draws per epoch", at_least(1, "an integer")),
    "partial_p0": Param(float, "partial fixing success rate (0: off)", within(0, 1, "a probability", open_hi=True)),
    "max_nodes": Param(int, "search nodes per epoch at most", at_least(1, "an integer")),
    "attitude": Param(str, "attitude from the fixed baselines", choices=("wls", "svd", "badshah", "baseline")),
    "pll_bandwidth_hz": Param(float, "PLL bandwidth (Hz)", POS),
    "dll_bandwidth_hz": Param(float, "DLL bandwidth (Hz)", POS),
    "correlator_spacing_chips": Param(float, "correlator spacing (chips)", POS),
    "integration_time_s": Param(float, "coherent integration time (s)", POS),
    "carrier_multipath_m": Param(float, "carrier multipath sd at the horizon (m)", NONNEG),
    "code_multipath_m": Param(float, "code multipath sd at the horizon (m)", NONNEG),
    "multipath_elevation_deg": Param(float, "e-folding elevation of the multipath (deg)", POS),
    "start_s": Param(float, "first epoch solved (s since start)", infinite=True),
    "stop_s": Param(float, "last epoch solved (s since start; inf: the end)", infinite=True),
    "every": Param(int, "every n-th epoch only", at_least(1, "an integer")),
    "float_epochs": Param(int, "float solution window (epochs)", at_least(1, "an integer")),
    "static": Param(int, "1: one baseline over the float window", **FLAG),
    "continuity": Param(int, "1: keep a fix until a loss of lock", **FLAG),
    "carrier_sigma_m": Param(float, "tdcp: carrier noise (m)", POS),
    "slip_threshold": Param(float, "tdcp: residual test (sigma)", POS),
    "troposphere": Param(int, "tdcp: 1 removes the modelled troposphere change", **FLAG),
    "lever_attitude": Param(str, "tdcp: attitude for the IMU-centre velocity",
                            choices=("auto", "attitude", "truth", "none")),
    "lever_rate": Param(str, "tdcp: lever-arm turn from the attitude or the IMU gyro", choices=("attitude", "imu")),
}

_NAMES = {float: "a number", int: "an integer", str: "a string", bool: "true or false"}


def spec(key: str, default) -> Param:
    """The schema entry of ``key``, else one inferred from its default's type."""
    if key in SCHEMA:
        return SCHEMA[key]
    if isinstance(default, list):
        return Param(float, "", shape=len(default))
    kind = next((k for k in (bool, str, int, float) if _is(default, k)), float)
    return Param(kind, "", optional=default is None, infinite=isinstance(default, float) and math.isinf(default))


def _is(value, kind) -> bool:
    """Type test where booleans are never numbers and integers are not floats' stand-ins (numpy scalars too)."""
    if kind is bool or kind is str:
        return isinstance(value, kind)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return False
    return isinstance(value, numbers.Integral) if kind is int else True


def check_value(p: Param, value):
    """``value`` converted (int -> float for float keys) when ``p`` accepts it; raises ValueError(what was
    expected) otherwise."""
    if value is None and p.optional:
        return None
    if p.shape is not None:
        want = f"a list of {p.shape} {_NAMES[p.kind].split(' ', 1)[-1]}s"
        if not isinstance(value, list) or len(value) != p.shape or not all(_is(v, p.kind) for v in value):
            raise ValueError(f"expected {want}")
        value = [_scalar(p, v) for v in value]
    else:
        if not _is(value, p.kind):
            raise ValueError(f"expected {_NAMES[p.kind]}" + (" (0 or 1)" if p.choices == (0, 1) else ""))
        value = _scalar(p, value)
    if p.choices is not None and value not in p.choices:
        raise ValueError(f"expected one of {', '.join(map(str, p.choices))}")
    problem = p.check(value) if p.check is not None else None
    if problem:
        raise ValueError(problem)
    return value


def _scalar(p: Param, v):
    if p.kind is float:
        v = float(v)
        if not (math.isfinite(v) or (p.infinite and not math.isnan(v))):
            raise ValueError("expected a finite number")
    elif p.kind is int:
        v = int(v)
    return v


def merge(defaults: dict, params: dict | None, solver: str, error: Callable = ScenarioError) -> dict:
    """``defaults`` overridden by ``params`` after checking each against the schema; ``error(key, message)``
    builds the exception (key ``estimator.<key>``): an unknown key names the solver and the known keys."""
    out = dict(defaults)
    for key, value in (params or {}).items():
        if key not in defaults:
            raise error(f"estimator.{key}", f"unknown key for --filter {solver} "
                                            f"(known: {', '.join(sorted(defaults))})")
        try:
            out[key] = check_value(spec(key, defaults[key]), value)
        except ValueError as exc:
            raise error(f"estimator.{key}", f"{exc}, got {value!r}") from None
    return out


def check_against_file(params: dict, defaults: dict, n_antennas: int, path, error: Callable = ScenarioError) -> None:
    """What the file decides: an antenna index below ``n_antennas`` (a file without antennas is left to the
    filter), and the antenna count a value needs (``align = "attitude"`` needs 3)."""
    for key, value in params.items():
        p = spec(key, defaults.get(key))
        if p.antenna_index and n_antennas and not 0 <= value < n_antennas:  # none: the filter says what it lacks
            raise error(f"estimator.{key}", f"expected 0 .. {n_antennas - 1} ({path} has {n_antennas} antennas), "
                                            f"got {value!r}")
        need = p.needs_antennas.get(value, 0) if p.needs_antennas else 0
        if n_antennas < need:
            raise error(f"estimator.{key}", f"{value!r} needs {need} or more antennas, {path} has {n_antennas}")


def parse_value(text: str):
    """A ``--set`` value: a TOML literal (number, bool, string, array, inline table) or else a bare string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def parse_set(items, prefix: str = "estimator.") -> dict:
    """``--set <prefix>key=value`` items -> {key: value}; values are TOML literals (:func:`parse_value`, as the
    scenario's ``--set``)."""
    out = {}
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep:
            raise ScenarioError("--set", f"expected {prefix}key=value, got {item!r}")
        if not key.startswith(prefix) or len(key) <= len(prefix):
            raise ScenarioError("--set", f"{key!r}: expected a key of the form {prefix}<name>")
        out[key[len(prefix):]] = parse_value(text.strip())
    return out
