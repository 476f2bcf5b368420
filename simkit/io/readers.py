"""Typed readers of a simkit file: the /truth, /imu and /gnss arrays of :mod:`.schema` as frozen dataclasses.

The consumers above the file (estimators, attitude, referee, plots, campaign metrics) read through these instead
of spelling dataset paths. Each reader takes an open :class:`~.reader.Dataset` and reads only what it is asked
(fields, signals, antennas, epochs), so a long file is read in bounded memory. An optional array the file does
not hold is None; a required one is a :class:`~simkit.errors.DataFileError` naming the file and dataset.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import frames, quat
from ..earth import C_LIGHT
from ..errors import DataFileError
from . import schema

# group names of :func:`has`, keyed so that callers need not spell HDF5 paths
GROUPS = {"truth": "truth", "imu": "imu", "imu_errors": "imu/errors", "gnss": "gnss", "antennas": "gnss/antennas",
          "obs": "gnss/obs", "gnss_truth": "gnss/truth"}
TRUTH_CORE = ("pos_ecef", "vel_enu", "quat_nb")


def path_of(group: str, name: str | None = None) -> str:
    """The HDF5 path of dataset ``name`` of ``group`` (a key of :data:`GROUPS`), or of the group, for messages."""
    return GROUPS[group] if name is None else f"{GROUPS[group]}/{name}"


def has(ds, group: str, name: str | None = None) -> bool:
    """True when ``ds`` holds the dataset ``name`` of ``group`` (a key of :data:`GROUPS`), or the group itself."""
    return path_of(group, name) in ds


def n_samples(ds, group: str) -> int:
    """The number of rows of ``group``'s time axis ("truth", "imu" or "gnss"; 0 when absent), without reading."""
    return len(ds[f"{GROUPS[group]}/t"]) if has(ds, group, "t") else 0


def members(ds, group: str) -> list[str]:
    """Names of the datasets directly under ``group`` (a key of :data:`GROUPS`; empty when absent)."""
    return ds.members(GROUPS[group])


def _require(ds, path: str, why: str):
    if path not in ds:
        raise DataFileError(ds.path, f"no /{path} dataset: {why}")


@dataclass(frozen=True)
class Truth:
    """Truth samples (:mod:`.schema` /truth): ``t`` (N,) s since start; ``pos_ecef`` (N, 3) m IMU centre;
    ``vel_enu`` (N, 3) m/s Earth-relative, ENU at the position; ``quat_nb`` (N, 4) body->ENU scalar-last;
    ``omega_ib_b`` (N, 3) rad/s body rate w.r.t. inertial space; ``lever_arm_b`` (A, 3) m the file's antenna
    lever arms; ``pos_lla`` (N, 3) rad, rad, m; ``euler`` (N, 3) rad pitch, roll, heading; ``f_ib_b`` (N, 3)
    m/s^2 specific force. A field not read (or not in the file) is None."""

    t: np.ndarray
    pos_ecef: np.ndarray | None = None
    vel_enu: np.ndarray | None = None
    quat_nb: np.ndarray | None = None
    omega_ib_b: np.ndarray | None = None
    lever_arm_b: np.ndarray | None = None
    pos_lla: np.ndarray | None = None
    euler: np.ndarray | None = None
    f_ib_b: np.ndarray | None = None


def truth_at(truth: Truth, t) -> Truth:
    """The truth at epochs ``t`` (K,) s inside its span, the one interpolation every consumer uses.

    Position: cubic Hermite in ECEF with the truth velocity (rotated from ENU to ECEF at each sample) when both are
    present, so the error is O(jerk dt^4) (below 1 um at 100 Hz for 10 g manoeuvres); linear otherwise. Velocity
    and body rate: linear (O(jerk dt^2 / 8), < 0.2 mm/s at 100 Hz and 10 m/s^3). Attitude: slerp of the body->ENU
    quaternions. At a sample time each field is that sample. Fields other than these four are None.
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
    if len(truth.t) == 1:
        i, s = np.zeros(t.size, int), np.zeros((t.size, 1))
        j = i
    else:
        i = np.clip(np.searchsorted(truth.t, t, side="right") - 1, 0, len(truth.t) - 2)
        j = i + 1
        s = ((t - truth.t[i]) / (truth.t[j] - truth.t[i]))[:, None]

    def linear(x):
        return None if x is None else (1 - s) * x[i] + s * x[j]

    pos = linear(truth.pos_ecef)
    if truth.pos_ecef is not None and truth.vel_enu is not None and len(truth.t) > 1:
        lat_lon = frames.ecef_to_lla(truth.pos_ecef[np.r_[i, j]])[:, :2]
        v = frames.enu_to_ecef_vec(truth.vel_enu[np.r_[i, j]], lat_lon[:, 0], lat_lon[:, 1])
        h = (truth.t[j] - truth.t[i])[:, None]
        h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
        pos = h00 * truth.pos_ecef[i] + h10 * h * v[:t.size] + h01 * truth.pos_ecef[j] + h11 * h * v[t.size:]
    att = None if truth.quat_nb is None else quat.slerp(truth.quat_nb[i], truth.quat_nb[j], s)
    return Truth(t, pos, linear(truth.vel_enu), att, linear(truth.omega_ib_b), truth.lever_arm_b)


def truth_rows(t_truth: np.ndarray, t_min: float | None, t_max: float | None) -> slice:
    """The rows of ``t_truth`` (N,) s that bracket [t_min, t_max] s (None: open end); all rows when fewer than
    two would remain (so that the caller can name both spans)."""
    lo = 0 if t_min is None else max(int(np.searchsorted(t_truth, t_min, side="right")) - 1, 0)
    hi = len(t_truth) if t_max is None else min(int(np.searchsorted(t_truth, t_max, side="left")) + 1, len(t_truth))
    return slice(0, len(t_truth)) if hi - lo < 2 else slice(lo, hi)


def read_truth(ds, t=None, fields=TRUTH_CORE + ("omega_ib_b",), span=None, required=TRUTH_CORE,
               tol_s: float = 0.0, epochs=None) -> Truth:
    """The /truth ``fields`` of ``ds`` (plus ``lever_arm_b`` from /gnss/antennas when present).

    ``epochs`` (a slice) reads those rows; ``span`` (t_min, t_max) s only the rows that bracket it
    (:func:`truth_rows`). ``t`` (K,) s instead
    gives the samples at those times: for each, the first truth sample at or after ``t - tol_s`` (the last one
    past the end); ``Truth.t`` is then the sample times. A ``required`` field the file lacks is an error."""
    for name in ("t", *required):
        _require(ds, f"truth/{name}", "the truth trajectory is needed here")
    t_all = ds["truth/t"][:]
    rows = truth_rows(t_all, *span) if span is not None else (slice(None) if epochs is None else epochs)
    if t is not None:
        rows = np.clip(np.searchsorted(t_all, np.asarray(t, float) - tol_s), 0, len(t_all) - 1)
    arrays = {k: _rows(ds[f"truth/{k}"], rows) for k in fields if f"truth/{k}" in ds}
    lever = ds["gnss/antennas/lever_arm_b"][:] if "gnss/antennas/lever_arm_b" in ds else None
    return Truth(t_all[rows], lever_arm_b=lever, **arrays)


def _rows(array, rows):
    """``array`` at ``rows`` (a slice or an index array; an index array reads the whole array once)."""
    return array[rows] if isinstance(rows, slice) else array[:][rows]


@dataclass(frozen=True)
class Imu:
    """IMU samples (:mod:`.schema` /imu): ``t`` (N,) s; ``gyro`` (N, 3) rad/s and ``accel`` (N, 3) m/s^2 body
    x right / y forward / z up; ``dtheta`` (N, 3) rad and ``dvel`` (N, 3) m/s increments (None unless the file
    holds increments); ``errors`` {term: (N, 3)} the true error processes asked for."""

    t: np.ndarray
    gyro: np.ndarray | None = None
    accel: np.ndarray | None = None
    dtheta: np.ndarray | None = None
    dvel: np.ndarray | None = None
    errors: dict = field(default_factory=dict)


def read_imu(ds, fields=("gyro", "accel", "dtheta", "dvel"), epochs=None, errors=()) -> Imu:
    """The /imu ``fields`` of ``ds`` that exist, at ``epochs`` (a slice; None: all), and the error ``terms``."""
    _require(ds, "imu/t", "the file has no IMU data")
    rows = slice(None) if epochs is None else epochs
    arrays = {k: ds[f"imu/{k}"][rows] for k in fields if f"imu/{k}" in ds}
    return Imu(ds["imu/t"][rows], **arrays, errors={k: ds[f"imu/errors/{k}"][rows] for k in errors})


@dataclass(frozen=True)
class Gnss:
    """A selection of /gnss (:mod:`.schema`): ``t`` (M,) s; ``sat_id`` (S,) str; ``signals`` the selected signal
    names, ``wavelength_m`` (G,) m and ``group_delay`` (S, G) m for them; ``lever_arm_b`` (A, 3) m body frame;
    ``sat_pos_ecef`` (M, S, 3) m and ``sat_clock`` (M, S) s; ``obs`` {kind: {signal: (M, A, S)}} and ``truth``
    {name: array} (names under /gnss/truth, e.g. "elevation" or "L1C/noise_code") as asked; an int antenna
    selection drops the antenna axis."""

    t: np.ndarray
    sat_id: np.ndarray
    signals: tuple
    wavelength_m: np.ndarray
    group_delay: np.ndarray | None
    lever_arm_b: np.ndarray
    sat_pos_ecef: np.ndarray | None = None
    sat_clock: np.ndarray | None = None
    obs: dict = field(default_factory=dict)
    truth: dict = field(default_factory=dict)
    sat_wavelength_m: np.ndarray | None = None  # (S, G) m per satellite (GLONASS FDMA); wavelength_m elsewhere


def gnss_signals(ds) -> tuple:
    """The signal names of /gnss/signals (empty when the file has no GNSS)."""
    return tuple(str(s) for s in ds["gnss/signals"][:]) if "gnss/signals" in ds else ()


def n_antennas(ds) -> int:
    """The number of antennas of /gnss/antennas/lever_arm_b (0 when the file has no GNSS)."""
    return ds["gnss/antennas/lever_arm_b"].shape[0] if "gnss/antennas/lever_arm_b" in ds else 0


def read_gnss(ds, signals=None, antennas=None, epochs=None, obs=(), truth=(), satellites=True) -> Gnss:
    """The /gnss arrays of ``ds`` for ``signals`` (names; None: all), ``antennas`` (an int, a slice or None: all)
    and ``epochs`` (a slice; None: all): observables of the ``obs`` kinds ("code", "carrier", ...), the
    /gnss/truth datasets named in ``truth`` (absent ones left out), and the satellite orbits and clocks unless
    ``satellites`` is False. An unknown signal is an error naming it and the file's signals."""
    _require(ds, "gnss/t", "the file has no GNSS data")
    have = gnss_signals(ds)
    names = have if signals is None else tuple(signals)
    bad = [s for s in names if s not in have]
    if bad:
        raise DataFileError(ds.path, f"/gnss/signals: no signal {bad[0]!r}, the file has {', '.join(have)}")
    cols = [have.index(s) for s in names]
    m = slice(None) if epochs is None else epochs
    a = slice(None) if antennas is None else antennas
    gd = ds["gnss/group_delay"][:][:, cols] if "gnss/group_delay" in ds else None
    sats = (ds["gnss/sat_pos_ecef"][m], ds["gnss/sat_clock"][m]) if satellites else (None, None)
    lam = ds["gnss/wavelength_m"][:][cols]
    n_sat = ds["gnss/sat_id"].shape[0]
    sat_lam = C_LIGHT / ds["gnss/sat_frequency_hz"][:][:, cols] if "gnss/sat_frequency_hz" in ds else \
        np.broadcast_to(lam, (n_sat, len(cols))).copy()  # files before FDMA signals: one wavelength per signal
    return Gnss(ds["gnss/t"][m], ds["gnss/sat_id"][:], names, lam, gd,
                ds["gnss/antennas/lever_arm_b"][:][a], *sats,
                obs={k: {s: ds[f"gnss/obs/{s}/{k}"][m, a] for s in names} for k in obs},
                truth={k: _gnss_truth(ds[f"gnss/truth/{k}"], f"gnss/truth/{k}", m, a) for k in truth
                       if f"gnss/truth/{k}" in ds},
                sat_wavelength_m=sat_lam)


def _gnss_truth(array, path: str, m, a):
    """The /gnss/truth array at ``path`` at epochs ``m`` and, where its declared shape has an antenna axis
    (M, A, ...), antennas ``a``; per-satellite arrays (M, S, ...) keep every satellite."""
    per_antenna = tuple(schema.field(path).shape[:2]) == ("M", "A")
    return array[m, a] if per_antenna else array[m]


def broadcast_ionosphere(ds):
    """{system: (alpha (4,), beta (4,))} the broadcast Klobuchar coefficients of /gnss/iono_*, None when the file
    predates them."""
    if "gnss/iono_alpha" not in ds:
        return None
    systems = [str(x) for x in ds["gnss/iono_systems"][:]]
    alpha, beta = ds["gnss/iono_alpha"][:], ds["gnss/iono_beta"][:]
    return {k: (alpha[i], beta[i]) for i, k in enumerate(systems)}


def broadcast_time_offsets(ds):
    """{system: (a0 s, a1 s/s, t_ref GPS week, t_ref s of week)} the broadcast system-time-minus-GPS-time
    polynomials of /gnss/time_offset applied to the simulated ranges; {} when the file has none."""
    if "gnss/time_offset" not in ds:
        return {}
    rows = ds["gnss/time_offset"][:]
    return {str(k): (float(r[0]), float(r[1]), int(r[2]), float(r[3]))
            for k, r in zip(ds["gnss/time_offset_systems"][:], rows)}


def reference_truth(ds) -> Truth | None:
    """The static /reference of a real file as a :class:`Truth` over its GNSS epochs (None without one): the
    position twice (first and last epoch), zero velocity, an identity attitude and zero body rate that only carry
    the file's antenna lever arms (zero for an imported file); never an attitude truth."""
    ref = read_reference(ds)
    if ref is None:
        return None
    t = ds["gnss/t"][:]
    span = np.array([t[0], t[-1] if t[-1] > t[0] else t[0] + 1.0])
    lever = ds["gnss/antennas/lever_arm_b"][:] if "gnss/antennas/lever_arm_b" in ds else np.zeros((1, 3))
    return Truth(span, np.tile(ref[0], (2, 1)), np.zeros((2, 3)), np.tile([0.0, 0.0, 0.0, 1.0], (2, 1)),
                 np.zeros((2, 3)), lever)


def read_reference(ds):
    """(pos_ecef (3,) m, source text, kind) of a real file's /reference (``simkit import``), None without one."""
    if "reference/pos_ecef" not in ds:
        return None
    attrs = ds.group_attrs("reference")
    return ds["reference/pos_ecef"][:], str(attrs.get("source", "unknown")), str(attrs.get("kind", "static"))
