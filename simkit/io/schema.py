"""The simkit HDF5 file, schema version 1: every dataset with its dtype, shape, units, frame and writing stage.

This module is the one definition of the file (the public contract third-party filters read). The writer refuses
a path, dtype or shape that is not declared here and takes the units from here; the reader, ``simkit inspect``,
the RINEX exporter, the ``/solutions`` writer and the README table (``python -m simkit.io.schema``) follow it.

Shape symbols: N truth/IMU samples, M GNSS epochs, A antennas, S satellites, G signals, K solution epochs,
X solution states, Y satellite systems with a broadcast ionosphere model, Z systems with a broadcast time offset
to GPS time applied, R campaign runs. Placeholders in paths: ``<signal>`` a signal name (``L1C``, ``B1I``, ...),
``<term>`` an IMU error term (``gyro_bias``, ``accel_white``, ...), ``<name>`` a solution name, ``<extra>`` a
filter's extra output.
"""
from __future__ import annotations

import functools
import re
from dataclasses import dataclass

SCHEMA_VERSION = 1

ROOT_ATTRS = {
    "schema_version": "schema version of the file (1)",
    "simkit_version": "simkit version that wrote the file",
    "scenario_toml": "the effective scenario (file text with every --set override applied), TOML",
    "seed": "the seed of the run",
    "start_gps_week": "GPS week of t = 0",
    "start_gps_sow": "GPS seconds of week of t = 0",
    "created_utc": "creation time, UTC ISO 8601",
    "scenario_name": "scenario.name",
    "overrides": "the --set overrides applied, JSON list of 'key=value'",
    "imported_from": "simkit import: the RINEX observation and navigation file names and the RINEX version, JSON",
    "import_report": "simkit import: what was kept and skipped (codes, systems, events), JSON",
}


@dataclass(frozen=True)
class Field:
    """One dataset of the file. ``shape`` holds symbols (str) and fixed sizes (int)."""

    path: str
    dtype: str          # numpy kind code: "f8", "i8", "u1", or "str"
    shape: tuple
    units: str
    frame: str
    stage: str
    meaning: str

    @property
    def pattern(self) -> re.Pattern:
        return re.compile("^" + re.sub(r"<\w+>", r"[^/]+", self.path) + "$")

    def shape_text(self) -> str:
        return "(" + ",".join(str(s) for s in self.shape) + ("," if len(self.shape) == 1 else "") + ")"


def _f(path, dtype, shape, units, frame, stage, meaning):
    return Field(path, dtype, tuple(shape), units, frame, stage, meaning)


_TRUTH = [
    _f("truth/t", "f8", ("N",), "s", "", "trajectory", "time since start at trajectory.rate_hz"),
    _f("truth/pos_ecef", "f8", ("N", 3), "m", "ECEF", "trajectory", "IMU centre position"),
    _f("truth/pos_lla", "f8", ("N", 3), "rad, rad, m", "WGS-84", "trajectory",
       "latitude, longitude, ellipsoidal height"),
    _f("truth/vel_enu", "f8", ("N", 3), "m/s", "ENU", "trajectory", "velocity relative to the Earth"),
    _f("truth/quat_nb", "f8", ("N", 4), "1 (x, y, z, w)", "body->ENU", "trajectory", "attitude quaternion, scalar last"),
    _f("truth/euler", "f8", ("N", 3), "rad", "body->ENU", "trajectory", "pitch, roll, heading"),
    _f("truth/omega_ib_b", "f8", ("N", 3), "rad/s", "body", "trajectory",
       "body rate w.r.t. inertial space (Earth rate included)"),
    _f("truth/f_ib_b", "f8", ("N", 3), "m/s^2", "body", "trajectory", "specific force"),
]
_IMU = [
    _f("imu/t", "f8", ("N",), "s", "", "imu", "sample times"),
    _f("imu/gyro", "f8", ("N", 3), "rad/s", "body", "imu", "measured angular rate"),
    _f("imu/accel", "f8", ("N", 3), "m/s^2", "body", "imu", "measured specific force"),
    _f("imu/dtheta", "f8", ("N", 3), "rad", "body", "imu", "angle increments (imu.output = \"increments\")"),
    _f("imu/dvel", "f8", ("N", 3), "m/s", "body", "imu", "velocity increments (imu.output = \"increments\")"),
    _f("imu/errors/<term>", "f8", ("N", 3), "rad/s or m/s^2", "body", "imu",
       "true error process (gyro_* in rad/s, accel_* in m/s^2); measured - truth = their sum"),
]
_GNSS = [
    _f("gnss/t", "f8", ("M",), "s", "", "gnss", "receiver epochs since start (true GPS time)"),
    _f("gnss/sat_id", "str", ("S",), "", "", "gnss",
       "satellite ids (RINEX 3: G GPS, C BDS, E Galileo, J QZSS, R GLONASS)"),
    _f("gnss/signals", "str", ("G",), "", "", "gnss", "signal names"),
    _f("gnss/frequency_hz", "f8", ("G",), "Hz", "", "gnss", "carrier frequency per signal"),
    _f("gnss/wavelength_m", "f8", ("G",), "m", "", "gnss", "carrier wavelength per signal"),
    _f("gnss/sat_frequency_hz", "f8", ("S", "G"), "Hz", "", "gnss",
       "carrier frequency per satellite and signal: frequency_hz, except GLONASS FDMA signals (channel k: "
       "G1 1602 + 0.5625 k MHz, G2 1246 + 0.4375 k MHz; NaN in an imported file that gives no k for a satellite); "
       "wavelength = c / this"),
    _f("gnss/group_delay", "f8", ("S", "G"), "m", "", "gnss", "code group delay applied (c TGD-type term)"),
    _f("gnss/iono_systems", "str", ("Y",), "", "", "gnss",
       "systems of the rows of iono_alpha/iono_beta: 'G' (GPS, L1 model) or 'C' (BDS, B1I model)"),
    _f("gnss/iono_alpha", "f8", ("Y", 4), "s, s/sc, s/sc^2, s/sc^3", "", "gnss",
       "broadcast Klobuchar amplitude coefficients of the navigation data (RINEX GPSA/BDSA; sc = semicircle); "
       "the simulated ionosphere is this model when gnss.errors.ionosphere is on"),
    _f("gnss/iono_beta", "f8", ("Y", 4), "s, s/sc, s/sc^2, s/sc^3", "", "gnss",
       "broadcast Klobuchar period coefficients (RINEX GPSB/BDSB)"),
    _f("gnss/time_offset_systems", "str", ("Z",), "", "", "gnss",
       "systems whose broadcast time offset to GPS time is applied (E Galileo GGTO, J QZSS, C BDS beyond 14 s); "
       "only when one is (gnss.errors.system_time_offset and a source that broadcasts it)"),
    _f("gnss/time_offset", "f8", ("Z", 4), "s, s/s, week, s", "", "gnss",
       "system time minus GPS time = a0 + a1 (t - t_ref) per row of time_offset_systems: a0, a1, t_ref GPS week, "
       "t_ref s of week (RINEX GAGP/QZGP/BDGP)"),
    _f("gnss/sat_pos_ecef", "f8", ("M", "S", 3), "m", "ECEF at emission", "gnss",
       "satellite at emission time for the IMU centre, in the ECEF frame of the emission epoch (RTKLIB satposs)"),
    _f("gnss/sat_clock", "f8", ("M", "S"), "s", "", "gnss",
       "satellite clock at emission: af0 + af1 dt + af2 dt^2 + relativity"),
    _f("gnss/antennas/lever_arm_b", "f8", ("A", 3), "m", "body", "gnss", "phase centre from the IMU centre"),
    _f("gnss/antennas/boresight_b", "f8", ("A", 3), "1", "body", "gnss", "antenna boresight direction"),
    _f("gnss/obs/<signal>/code", "f8", ("M", "A", "S"), "m", "", "gnss", "pseudorange; NaN where not tracked"),
    _f("gnss/obs/<signal>/carrier", "f8", ("M", "A", "S"), "cycles", "", "gnss", "carrier phase"),
    _f("gnss/obs/<signal>/doppler", "f8", ("M", "A", "S"), "Hz", "", "gnss",
       "Doppler, positive for an approaching satellite"),
    _f("gnss/obs/<signal>/cn0", "f8", ("M", "A", "S"), "dB-Hz", "", "gnss", "carrier-to-noise density"),
    _f("gnss/obs/<signal>/ambiguity", "i8", ("M", "A", "S"), "cycles", "", "gnss",
       "true integer ambiguity (changes only at a slip)"),
    _f("gnss/obs/<signal>/lli", "u1", ("M", "A", "S"), "", "", "gnss", "loss-of-lock flags (RINEX bit 0)"),
    _f("gnss/truth/antenna_pos_ecef", "f8", ("M", "A", 3), "m", "ECEF", "gnss", "antenna phase centres"),
    _f("gnss/truth/antenna_vel_ecef", "f8", ("M", "A", 3), "m/s", "ECEF", "gnss", "phase-centre velocities"),
    _f("gnss/truth/range", "f8", ("M", "A", "S"), "m", "", "gnss",
       "geometric range to the true satellite (light time and Earth rotation included)"),
    _f("gnss/truth/range_rate", "f8", ("M", "A", "S"), "m/s", "", "gnss", "exact derivative of the range"),
    _f("gnss/truth/elevation", "f8", ("M", "A", "S"), "rad", "ENU", "gnss", "elevation at each antenna"),
    _f("gnss/truth/azimuth", "f8", ("M", "A", "S"), "rad", "ENU", "gnss", "azimuth, clockwise from north"),
    _f("gnss/truth/receiver_clock", "f8", ("M", "A"), "m", "", "gnss", "c dt_a"),
    _f("gnss/truth/receiver_clock_drift", "f8", ("M", "A"), "m/s", "", "gnss", "c dt_a'"),
    _f("gnss/truth/satellite_clock", "f8", ("M", "A", "S"), "m", "", "gnss", "-c dT^s"),
    _f("gnss/truth/satellite_clock_drift", "f8", ("M", "A", "S"), "m/s", "", "gnss", "-c dT^s' (1 - rho'/c)"),
    _f("gnss/truth/troposphere", "f8", ("M", "A", "S"), "m", "", "gnss", "slant tropospheric delay"),
    _f("gnss/truth/troposphere_rate", "f8", ("M", "A", "S"), "m/s", "", "gnss", "its rate"),
    _f("gnss/truth/los_state", "u1", ("M", "A", "S"), "", "", "gnss",
       "line of sight (with an [environment]): 0 direct, 1 direct plus reflection, 2 reflection only (NLOS), "
       "3 blocked, 255 not above the horizon"),
    _f("gnss/truth/nlos_delay", "f8", ("M", "A", "S"), "m", "", "gnss",
       "extra path of the received reflection (with an [environment]; states 1 and 2), 0 where direct only, "
       "NaN where blocked or below the horizon"),
    _f("gnss/truth/shadow_state", "u1", ("M", "A", "S"), "", "", "gnss",
       "street shadowing channel (with [gnss.shadowing]): 0 line of sight, 1 shadowed, 2 blocked (not tracked), "
       "255 no chain (below the horizon margin)"),
    _f("gnss/truth/shadow_attenuation", "f8", ("M", "A", "S"), "dB", "", "gnss",
       "shadowing attenuation taken off C/N0 (with [gnss.shadowing]): 0 in line of sight, NaN where blocked or "
       "no chain"),
    _f("gnss/truth/ionosphere_model_error", "f8", ("M", "A", "S"), "m", "", "gnss",
       "truth minus broadcast Klobuchar ionosphere, at L1 (GPS) / B1I (BDS); 0 with truth_errors none"),
    _f("gnss/truth/troposphere_model_error", "f8", ("M", "A", "S"), "m", "", "gnss",
       "truth minus the Saastamoinen 1/sin(el) troposphere a receiver applies"),
    _f("gnss/truth/orbit_range_error", "f8", ("M", "A", "S"), "m", "", "gnss",
       "range to the true satellite minus range to the broadcast one (/gnss/sat_pos_ecef)"),
    _f("gnss/truth/orbit_error_rac", "f8", ("M", "S", 3), "m", "radial, along, cross", "gnss",
       "true minus broadcast satellite position"),
    _f("gnss/truth/satellite_clock_error", "f8", ("M", "S"), "m", "", "gnss",
       "true minus broadcast satellite clock term -c dT^s (as it enters the code)"),
    _f("gnss/truth/system_time_offset", "f8", ("M", "S"), "m", "", "gnss",
       "-c (system time - GPS time) of each satellite's system, part of truth/satellite_clock and of every range "
       "(only when /gnss/time_offset is written)"),
    _f("gnss/truth/<signal>/ionosphere", "f8", ("M", "A", "S"), "m", "", "gnss",
       "code delay (the carrier gets minus this)"),
    _f("gnss/truth/<signal>/ionosphere_rate", "f8", ("M", "A", "S"), "m/s", "", "gnss", "its rate"),
    _f("gnss/truth/<signal>/multipath_code", "f8", ("M", "A", "S"), "m", "", "gnss", "code multipath"),
    _f("gnss/truth/<signal>/multipath_carrier", "f8", ("M", "A", "S"), "m", "", "gnss", "carrier multipath"),
    _f("gnss/truth/<signal>/multipath_rate", "f8", ("M", "A", "S"), "m/s", "", "gnss",
       "rate of the carrier multipath in the Doppler (with an [environment]: two-ray or NLOS term)"),
    _f("gnss/truth/<signal>/noise_code", "f8", ("M", "A", "S"), "m", "", "gnss", "code thermal-noise draw"),
    _f("gnss/truth/<signal>/noise_carrier", "f8", ("M", "A", "S"), "m", "", "gnss", "carrier thermal-noise draw"),
    _f("gnss/truth/<signal>/noise_doppler", "f8", ("M", "A", "S"), "Hz", "", "gnss", "Doppler noise draw"),
    _f("gnss/truth/<signal>/sigma_code", "f8", ("M", "A", "S"), "m", "", "gnss", "code noise sigma"),
    _f("gnss/truth/<signal>/sigma_carrier", "f8", ("M", "A", "S"), "m", "", "gnss", "carrier noise sigma"),
    _f("gnss/truth/<signal>/sigma_doppler", "f8", ("M", "A", "S"), "Hz", "", "gnss", "Doppler noise sigma"),
    _f("gnss/truth/<signal>/cn0", "f8", ("M", "A", "S"), "dB-Hz", "", "gnss",
       "true C/N0 behind the reported estimate (with [gnss.cn0_report])"),
]
_REFERENCE = [
    _f("reference/pos_ecef", "f8", (3,), "m", "ECEF", "import",
       "reference position of a real file's antenna (no /truth): source in the group's 'source' attribute"),
]
_SOLUTIONS = [
    _f("solutions/<name>/t", "f8", ("K",), "s", "", "estimators", "solution epochs since start"),
    _f("solutions/<name>/pos_ecef", "f8", ("K", 3), "m", "ECEF", "estimators",
       "estimated position of the group's point attribute (imu, antenna:K, lever_b:[x,y,z]; imu when absent)"),
    _f("solutions/<name>/vel_enu", "f8", ("K", 3), "m/s", "ENU", "estimators", "estimated velocity of that point"),
    _f("solutions/<name>/quat_nb", "f8", ("K", 4), "1 (x, y, z, w)", "body->ENU", "estimators", "estimated attitude"),
    _f("solutions/<name>/euler", "f8", ("K", 3), "rad", "body->ENU", "estimators", "pitch, roll, heading"),
    _f("solutions/<name>/cov", "f8", ("K", "X", "X"), "SI", "", "estimators",
       "state covariance, in the order of state_names"),
    _f("solutions/<name>/state_names", "str", ("X",), "", "", "estimators", "names of the filter states"),
    _f("solutions/<name>/extras/<extra>", "any", ("K", "..."), "see attribute", "", "estimators",
       "filter-specific outputs (biases, lever arm, gamma, ambiguities, ratio, ...)"),
]

_CAMPAIGN = [
    _f("campaign/runs/<column>", "any", ("R",), "see attribute", "", "campaign",
       "campaign index (DIR/index.h5): one column of the per-run table (run_id, seed, status, metrics, ...)"),
    _f("campaign/virtual/<path>", "any", ("R", "..."), "as the run files", "", "campaign",
       "campaign index: virtual dataset stacking one dataset of every completed run file (/ written as .)"),
]

SCHEMA: tuple[Field, ...] = tuple(_TRUTH + _IMU + _GNSS + _REFERENCE + _SOLUTIONS + _CAMPAIGN)

GROUP_ATTRS = {
    "truth": {"rate_hz": "trajectory.rate_hz",
              "log": "a logged trajectory only (trajectory.source): JSON of source, sha256, samples_used, attitude, "
                     "sigma_m, sigma_source, residual_rms_m"},
    "imu": {"rate_hz": "IMU rate", "<parameter>": "the IMU error model parameters (JSON text where not scalar)"},
    "gnss": {"rate_hz": "gnss.rate_hz", "receiver": "simkit import: RINEX receiver type",
             "antenna": "simkit import: RINEX antenna type", "marker": "simkit import: RINEX marker name"},
    "reference": {"source": "where /reference/pos_ecef comes from (RINEX header or user)", "kind": "static"},
    "solutions/<name>": {"config": "the estimator configuration, JSON"},
}


class SchemaError(ValueError):
    """A path, dtype or shape that schema version 1 does not declare."""


@functools.lru_cache(maxsize=4096)  # a campaign index checks the same few hundred paths for every run
def field(path: str) -> Field:
    """The declared :class:`Field` of a concrete dataset path (leading '/' optional)."""
    path = path.lstrip("/")
    for f in SCHEMA:
        if f.pattern.match(path):
            return f
    raise SchemaError(f"{path}: not a dataset of simkit schema v{SCHEMA_VERSION}")


def check(path: str, dtype, shape: tuple) -> Field:
    """The :class:`Field` of ``path`` after checking that an array of ``dtype`` and ``shape`` may be stored there."""
    import numpy as np

    f = field(path)
    kind = np.dtype(dtype)
    if f.dtype == "str":
        ok = kind.kind in "USO"
    elif f.dtype == "any":
        ok = True
    else:
        ok = kind == np.dtype(f.dtype)
    if not ok:
        raise SchemaError(f"{path}: dtype {kind} where the schema declares {f.dtype}")
    if "..." not in f.shape:
        if len(shape) != len(f.shape) or any(isinstance(s, int) and s != n for s, n in zip(f.shape, shape)):
            raise SchemaError(f"{path}: shape {tuple(shape)} where the schema declares {f.shape_text()}")
    return f


def markdown_table() -> str:
    """The README's dataset table, generated from :data:`SCHEMA`."""
    rows = ["| path | shape | dtype | units | frame | meaning |", "|---|---|---|---|---|---|"]
    for f in SCHEMA:
        rows.append(f"| /{f.path} | {f.shape_text()} | {f.dtype} | {f.units} | {f.frame} | {f.meaning} |")
    return "\n".join(rows)


if __name__ == "__main__":
    print(markdown_table())
