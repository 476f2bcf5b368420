"""The [gnss.truth_errors] table: how far the simulated truth departs from the models a receiver applies.

A receiver corrects its code with the broadcast Klobuchar ionosphere, a standard-atmosphere Saastamoinen
troposphere mapped with 1/sin(el), and the broadcast orbit and clock. With ``model = "realistic"`` (the default) the
simulated truth departs from each of them by a documented amount (see docs/truth_errors.md for the sources of the
defaults); ``model = "none"`` makes the truth equal to those models again (simkit before issue 21). Every parameter is
a plain scenario key (``gnss.truth_errors.<key>``) so that a fit to a real receiver can set it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..section import Section, in_range, non_negative, positive

MODELS = ("realistic", "none")
TROPO_MAPPINGS = ("niell", "model")


@dataclass(frozen=True)
class EphemerisErrorConfig:
    """Broadcast orbit and clock error of one system: 1-sigma radial, along-track, cross-track orbit error (3,) m
    and clock error m (RMS over an ephemeris interval), and the interval between ephemeris updates (s)."""

    orbit_sigma_rac_m: tuple[float, float, float]
    clock_sigma_m: float
    interval_s: float
    geosync_scale: float = 1.0     # factor on both for geosynchronous (GEO, IGSO) satellites


@dataclass(frozen=True)
class TruthErrorsConfig:
    model: str                                   # "realistic" or "none"
    iono_residual_fraction: float                # RMS of (true - k Klobuchar) / (k Klobuchar)
    iono_scale: float                            # k: the truth's mean ratio to Klobuchar
    iono_correlation_length_km: float            # of the residual field at the pierce points
    iono_correlation_time_s: float
    ionex_file: str | None                       # a global ionosphere map: the truth ionosphere when given
    tropo_mapping: str                           # "niell" (truth maps with NMF) or "model" (1/sin(el), as the receiver)
    tropo_zhd_sigma_m: float                     # constant zenith hydrostatic offset from the standard atmosphere
    tropo_zwd_sigma_m: float                     # constant zenith wet offset
    tropo_zwd_random_walk_m_per_sqrt_h: float    # slowly varying zenith wet delay
    ephemeris: dict                              # system letter "G"/"C" -> EphemerisErrorConfig

    @property
    def on(self) -> bool:
        return self.model != "none"


_REALISTIC = {
    "iono_residual_fraction": 0.5, "iono_scale": 1.0, "iono_correlation_length_km": 1000.0,
    "iono_correlation_time_s": 3600.0,
    "tropo_mapping": "niell", "tropo_zhd_sigma_m": 0.02, "tropo_zwd_sigma_m": 0.04,
    "tropo_zwd_random_walk_m_per_sqrt_h": 0.01,
    "gps_orbit_sigma_rac_m": [0.15, 0.6, 0.4], "gps_clock_sigma_m": 0.5, "gps_ephemeris_interval_s": 7200.0,
    "bds_orbit_sigma_rac_m": [0.3, 1.2, 0.8], "bds_clock_sigma_m": 0.9, "bds_ephemeris_interval_s": 3600.0,
    "bds_geo_igso_sigma_scale": 1.0,
}
_NONE = dict(_REALISTIC, iono_residual_fraction=0.0, tropo_mapping="model", tropo_zhd_sigma_m=0.0,
             tropo_zwd_sigma_m=0.0, tropo_zwd_random_walk_m_per_sqrt_h=0.0, gps_orbit_sigma_rac_m=[0.0] * 3,
             gps_clock_sigma_m=0.0, bds_orbit_sigma_rac_m=[0.0] * 3, bds_clock_sigma_m=0.0)
KEYS = tuple(_REALISTIC) + ("ionex_file",)


def realistic_defaults() -> dict:
    """The ``realistic`` parameter values (a copy), key -> value."""
    return {k: (list(v) if isinstance(v, list) else v) for k, v in _REALISTIC.items()}


def parse_truth_errors(sec: Section) -> TruthErrorsConfig:
    """Read and validate ``[gnss.truth_errors]`` (``sec`` at path "gnss.truth_errors")."""
    model = sec.get("model", str, "realistic", choices=MODELS)
    if model == "none":
        given = [k for k in KEYS if sec.has(k)]
        if given:
            raise sec.error(given[0], 'has no effect with model = "none" (remove it, or use model = "realistic")')
    d = _REALISTIC if model == "realistic" else _NONE
    ephemeris = {}
    for letter, name in (("G", "gps"), ("C", "bds")):
        ephemeris[letter] = EphemerisErrorConfig(
            orbit_sigma_rac_m=tuple(sec.get(f"{name}_orbit_sigma_rac_m", float, d[f"{name}_orbit_sigma_rac_m"],
                                            shape=3, check=_all_non_negative)),
            clock_sigma_m=sec.get(f"{name}_clock_sigma_m", float, d[f"{name}_clock_sigma_m"], check=non_negative),
            interval_s=sec.get(f"{name}_ephemeris_interval_s", float, d[f"{name}_ephemeris_interval_s"],
                               check=in_range(60.0, 86400.0)),
            geosync_scale=sec.get("bds_geo_igso_sigma_scale", float, d["bds_geo_igso_sigma_scale"],
                                  check=in_range(0.0, 20.0)) if letter == "C" else 1.0)
    ionex = sec.get("ionex_file", str, None)
    if ionex is not None and not ionex.strip():
        raise sec.error("ionex_file", "expected a file path, got an empty string")
    cfg = TruthErrorsConfig(
        model=model,
        iono_residual_fraction=sec.get("iono_residual_fraction", float, d["iono_residual_fraction"],
                                       check=in_range(0.0, 5.0)),
        iono_scale=sec.get("iono_scale", float, d["iono_scale"], check=in_range(0.0, 5.0)),
        iono_correlation_length_km=sec.get("iono_correlation_length_km", float, d["iono_correlation_length_km"],
                                           check=positive),
        iono_correlation_time_s=sec.get("iono_correlation_time_s", float, d["iono_correlation_time_s"],
                                        check=positive),
        ionex_file=ionex,
        tropo_mapping=sec.get("tropo_mapping", str, d["tropo_mapping"], choices=TROPO_MAPPINGS),
        tropo_zhd_sigma_m=sec.get("tropo_zhd_sigma_m", float, d["tropo_zhd_sigma_m"], check=in_range(0.0, 1.0)),
        tropo_zwd_sigma_m=sec.get("tropo_zwd_sigma_m", float, d["tropo_zwd_sigma_m"], check=in_range(0.0, 1.0)),
        tropo_zwd_random_walk_m_per_sqrt_h=sec.get("tropo_zwd_random_walk_m_per_sqrt_h", float,
                                                   d["tropo_zwd_random_walk_m_per_sqrt_h"], check=in_range(0.0, 1.0)),
        ephemeris=ephemeris)
    sec.done()
    return cfg


def _all_non_negative(v):
    return None if np.all(np.asarray(v) >= 0.0) else "must be >= 0 in every component"
