"""What the GNSS stage returns: plain frozen dataclasses of numpy arrays (the pipeline maps them to the file).

Shapes: M epochs, A antennas, S satellites, G signals. Units and frames are those of ``simkit/io/schema.py``
(``/gnss/...``), where every field is declared.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class GnssStatic:
    """Time-independent description: ids (S,), signal names, frequencies and wavelengths (G,), group delays
    (S, G) m, antenna lever arms and boresights (A, 3) in body axes, and the broadcast Klobuchar coefficients
    (Y, 4) per system of ``iono_systems`` (Y,) ('G', 'C'), alpha in s, s/sc, s/sc^2, s/sc^3 and beta likewise."""

    sat_id: np.ndarray
    signals: np.ndarray
    frequency_hz: np.ndarray
    wavelength_m: np.ndarray
    sat_frequency_hz: np.ndarray   # (S, G) Hz: per satellite (GLONASS FDMA channels), else frequency_hz
    group_delay: np.ndarray
    lever_arm_b: np.ndarray
    boresight_b: np.ndarray
    iono_systems: np.ndarray
    iono_alpha: np.ndarray
    iono_beta: np.ndarray
    time_offset_systems: np.ndarray | None = None  # (Z,) systems whose broadcast time offset to GPS is applied
    time_offset: np.ndarray | None = None          # (Z, 4): a0 s, a1 s/s, t_ref GPS week, t_ref s of week


@dataclass(frozen=True)
class SignalObs:
    """Observables of one signal (M, A, S): code m, carrier cycles, Doppler Hz, C/N0 dB-Hz (NaN where not
    tracked), true ambiguity (int64 cycles), LLI (uint8)."""

    code: np.ndarray
    carrier: np.ndarray
    doppler: np.ndarray
    cn0: np.ndarray
    ambiguity: np.ndarray
    lli: np.ndarray


@dataclass(frozen=True)
class SignalTruth:
    """Error terms of one signal (M, A, S): ionosphere (code delay) and its rate, multipath, the thermal-noise
    draws and their standard deviations."""

    ionosphere: np.ndarray
    ionosphere_rate: np.ndarray
    multipath_code: np.ndarray
    multipath_carrier: np.ndarray
    noise_code: np.ndarray
    noise_carrier: np.ndarray
    noise_doppler: np.ndarray
    sigma_code: np.ndarray
    sigma_carrier: np.ndarray
    sigma_doppler: np.ndarray
    multipath_rate: np.ndarray | None = None   # with an [environment]: rate of multipath_carrier in the Doppler
    cn0: np.ndarray | None = None   # with [gnss.cn0_report]: the true C/N0 (dB-Hz) behind the reported estimate


@dataclass(frozen=True)
class GnssTruth:
    """Signal-independent truth: antenna phase centres (M, A, 3), geometry and clocks (M, A, S) or (M, A),
    troposphere (M, A, S); the truth minus the receiver's models (docs/truth_errors.md): ionosphere at the system's
    reference frequency and troposphere (M, A, S), range to the true minus the broadcast satellite (M, A, S), orbit
    error in radial/along/cross axes (M, S, 3) and the satellite clock term's error (M, S), all m."""

    antenna_pos_ecef: np.ndarray
    antenna_vel_ecef: np.ndarray
    range: np.ndarray
    range_rate: np.ndarray
    elevation: np.ndarray
    azimuth: np.ndarray
    receiver_clock: np.ndarray
    receiver_clock_drift: np.ndarray
    satellite_clock: np.ndarray
    satellite_clock_drift: np.ndarray
    troposphere: np.ndarray
    troposphere_rate: np.ndarray
    ionosphere_model_error: np.ndarray
    troposphere_model_error: np.ndarray
    orbit_range_error: np.ndarray
    orbit_error_rac: np.ndarray
    satellite_clock_error: np.ndarray
    los_state: np.ndarray | None = None        # with an [environment]: (M, A, S) uint8, see simkit.environment
    nlos_delay: np.ndarray | None = None       # with an [environment]: (M, A, S) m, extra path of the reflection
    system_time_offset: np.ndarray | None = None  # (M, S) m: -c (system time - GPS time), when one is applied
    shadow_state: np.ndarray | None = None     # with [gnss.shadowing]: (M, A, S) uint8, see simkit.gnss.shadowing
    shadow_attenuation: np.ndarray | None = None  # with [gnss.shadowing]: (M, A, S) dB taken off C/N0


@dataclass(frozen=True)
class GnssEpochs:
    """One block of receiver epochs: times ``t`` (M,) s, satellite states (M, S, 3) m ECEF of the emission epoch
    and clocks (M, S) s, the truth, and per signal name the observables and their error terms."""

    t: np.ndarray
    sat_pos_ecef: np.ndarray
    sat_clock: np.ndarray
    truth: GnssTruth
    obs: dict[str, SignalObs]
    signal_truth: dict[str, SignalTruth]
