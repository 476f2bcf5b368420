"""The [gnss] scenario section: typed, validated configuration of the GNSS observables stage.

Every key carries its unit in its name; see docs/gnss.md for the full table. ``parse_config(section)`` calls
``done()`` on every table it reads, so a misspelt key is an error naming its dotted path.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ScenarioError
from ..section import Section, in_range, non_negative, positive
from . import clock, signals
from .acquisition import AcquisitionConfig, parse_acquisition
from .cn0_report import Cn0ReportConfig, parse_cn0_report
from .shadowing import ShadowingConfig, parse_shadowing
from .truth_config import TruthErrorsConfig, parse_truth_errors

ERROR_TERMS = ("receiver_clock", "satellite_clock", "group_delay", "ionosphere", "troposphere", "multipath",
               "noise", "cycle_slips", "system_time_offset")


@dataclass(frozen=True)
class Antenna:
    lever_arm_b: np.ndarray      # (3,) m, phase centre from the IMU centre, body frame
    boresight_b: np.ndarray      # (3,) unit vector, body frame
    horizon_mask_rad: float      # satellites less than this above the antenna's horizon plane are masked
    rolloff_db: float            # gain at the antenna horizon relative to boresight (dB, >= 0)
    gain_pattern: tuple | None = None   # ((off-boresight deg, ...), (gain dB, ...)): replaces the rolloff


@dataclass(frozen=True)
class NoiseConfig:
    model: str                   # "cn0" (tracking-loop jitter from C/N0) or "constant"
    code_sigma_m: float
    carrier_sigma_m: float
    doppler_sigma_hz: float
    dll_bandwidth_hz: float
    pll_bandwidth_hz: float
    fll_bandwidth_hz: float
    correlator_spacing_chips: float
    integration_time_s: float


@dataclass(frozen=True)
class MultipathConfig:
    code_sigma_m: float          # at the horizon
    carrier_sigma_m: float       # at the horizon
    elevation_scale_rad: float
    correlation_time_s: float
    signal_correlation_time_s: dict = field(default_factory=dict)   # signal -> s, where not correlation_time_s


@dataclass(frozen=True)
class ScheduledSlip:
    t_s: float
    sat: str | None              # None: every satellite
    antenna: int | None          # None: every antenna
    signal: str | None           # None: every signal
    cycles: int | None           # None: a random non-zero jump


@dataclass(frozen=True)
class Outage:
    start_s: float
    end_s: float
    sats: tuple[str, ...] | None
    antennas: tuple[int, ...] | None


@dataclass(frozen=True)
class GnssConfig:
    rate_hz: float
    elevation_mask_rad: float
    sources: tuple[str, ...]
    antennas: tuple[Antenna, ...]
    signals: tuple[str, ...]
    clock_mode: str              # "per_antenna" or "common"
    oscillator: clock.Oscillator
    oscillator_name: str
    errors: dict[str, bool]
    cn0_zenith_dbhz: float
    noise: NoiseConfig
    multipath: MultipathConfig
    slip_rate_per_h: float
    slips: tuple[ScheduledSlip, ...]
    outages: tuple[Outage, ...]
    ambiguity_max_cycles: int
    iono_coefficients: dict[str, tuple] = field(default_factory=dict)  # "gps"/"bds" -> (alpha, beta) overrides
    code_error_scale: dict = field(default_factory=dict)  # signal -> factor (or (el_deg, factor) table) on code noise + multipath
    cn0_offset_db: dict = field(default_factory=dict)  # signal -> dB (or (off_boresight_deg, dB) table) added to the table's C/N0 offset
    satellite_cn0_offset_db: dict = field(default_factory=dict)  # signal -> {satellite id: dB} on top of it
    truth_errors: TruthErrorsConfig | None = None  # departures of the truth from the receiver's models; None: off
    acquisition: AcquisitionConfig = field(default_factory=AcquisitionConfig)  # rising satellites' first track
    shadowing: ShadowingConfig | None = None  # stochastic street shadowing / blockage of C/N0; None: off
    cn0_report: Cn0ReportConfig | None = None  # the receiver's C/N0 estimate noise and resolution; None: exact

    @property
    def nav_systems(self) -> str:
        """System letters to read from RINEX navigation sources: GPS and BDS always (as before Galileo, GLONASS
        and QZSS existed, so GPS/BDS scenarios keep their satellites), plus each system with a configured
        signal."""
        wanted = {"G", "C"} | {signals.SIGNALS[n].system for n in self.signals}
        return "".join(c for c in "GCEJR" if c in wanted)


def _unit(v, key_section: Section, name: str) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    n = np.linalg.norm(v)
    if n == 0.0:
        raise key_section.error(name, "must be a non-zero vector")
    return v / n


def parse_config(sec: Section) -> GnssConfig:
    """Read and validate the [gnss] table (``sec`` at path "gnss"). Raises ScenarioError naming the key."""
    rate = sec.get("rate_hz", float, 1.0, check=positive)
    mask = sec.get("elevation_mask_deg", float, 10.0, check=in_range(-90.0, 90.0))
    sigs = _signals(sec)
    sources = [c.get("source", str) for c in _each(sec.sections("constellation", required=True))]
    if not sources:
        raise sec.error("constellation", "expected at least one [[gnss.constellation]]")
    antennas = [_antenna(a) for a in _each(sec.sections("antenna", required=True))]
    if not antennas:
        raise sec.error("antenna", "expected at least one [[gnss.antenna]]")
    clock_mode = sec.get("clock", str, "common", choices=("common", "per_antenna"))
    osc_name = sec.get("oscillator", str, "tcxo", choices=tuple(clock.PRESETS))
    err = sec.section("errors")
    errors = {k: err.get(k, bool, True) for k in ERROR_TERMS}
    err.done()
    cfg = GnssConfig(
        rate_hz=rate, elevation_mask_rad=np.radians(mask), sources=tuple(sources), antennas=tuple(antennas),
        signals=tuple(sigs), clock_mode=clock_mode, oscillator=clock.PRESETS[osc_name], oscillator_name=osc_name,
        errors=errors, cn0_zenith_dbhz=sec.get("cn0_zenith_dbhz", float, 45.0, check=in_range(10.0, 70.0)),
        noise=_noise(sec.section("noise")), multipath=_multipath(sec.section("multipath"), sigs),
        slip_rate_per_h=sec.get("slip_rate_per_h", float, 0.0, check=non_negative),
        slips=tuple(_slip(s, sigs, len(antennas)) for s in _each(sec.sections("slip"))),
        outages=tuple(_outage(o, len(antennas)) for o in _each(sec.sections("outage"))),
        ambiguity_max_cycles=sec.get("ambiguity_max_cycles", int, 100000, check=in_range(0, 10**8)),
        iono_coefficients=_ionosphere(sec.section("ionosphere")),
        code_error_scale=_code_scale(sec.section("code_error_scale"), sigs),
        cn0_offset_db=_cn0_offset(sec.section("cn0_offset_db"), sigs),
        satellite_cn0_offset_db=_satellite_cn0_offset(sec.section("satellite_cn0_offset_db"), sigs),
        truth_errors=parse_truth_errors(sec.section("truth_errors")),
        acquisition=parse_acquisition(sec.section("acquisition")),
        shadowing=parse_shadowing(sec.section("shadowing")),
        cn0_report=parse_cn0_report(sec.section("cn0_report")))
    sec.done()
    return cfg


def _each(sections):
    """Yield each sub-table, then reject its unknown keys (after the caller read what it knows)."""
    for s in sections:
        yield s
        s.done()


def _signals(sec: Section) -> list[str]:
    sigs = sec.get("signals", str, ["L1C"], shape=0)
    if not sigs:
        raise sec.error("signals", "expected at least one signal")
    for s in sigs:
        if s not in signals.SIGNALS:
            raise sec.error("signals", f"unknown signal {s!r} (known: {', '.join(signals.SIGNALS)})")
    if len(set(sigs)) != len(sigs):
        raise sec.error("signals", f"duplicate signal in {sigs!r}")
    return sigs


def _antenna(a: Section) -> Antenna:
    pattern = None
    if a.has("gain_pattern"):
        if a.has("rolloff_db"):
            raise a.error("gain_pattern", "cannot be given with rolloff_db: the pattern replaces the rolloff")
        pattern = _gain_pattern(a.section("gain_pattern"))
    return Antenna(
        lever_arm_b=np.asarray(a.get("lever_arm_m", float, shape=3)),
        boresight_b=_unit(a.get("boresight_b", float, [0.0, 0.0, 1.0], shape=3), a, "boresight_b"),
        horizon_mask_rad=np.radians(a.get("horizon_mask_deg", float, 0.0, check=in_range(-90.0, 90.0))),
        rolloff_db=a.get("rolloff_db", float, 10.0, check=non_negative), gain_pattern=pattern)


def _gain_pattern(t: Section) -> tuple:
    """``gain_pattern = {off_boresight_deg = [...], gain_db = [...]}``: the antenna gain relative to the zenith
    C/N0 at increasing angles from the boresight in [0, 180] (linear in between, the end values beyond)."""
    off = t.get("off_boresight_deg", float, shape=0)
    gain = t.get("gain_db", float, shape=0)
    if not off or len(off) != len(gain):
        raise t.error("gain_db", f"expected one gain per angle ({len(off)}), got {len(gain)}")
    if any(b <= a for a, b in zip(off, off[1:])) or not all(0.0 <= x <= 180.0 for x in off):
        raise t.error("off_boresight_deg", f"expected increasing angles in [0, 180], got {off!r}")
    t.done()
    return tuple(off), tuple(gain)


def _noise(nz: Section) -> NoiseConfig:
    cfg = NoiseConfig(
        model=nz.get("model", str, "cn0", choices=("cn0", "constant")),
        code_sigma_m=nz.get("code_sigma_m", float, 0.3, check=non_negative),
        carrier_sigma_m=nz.get("carrier_sigma_m", float, 0.002, check=non_negative),
        doppler_sigma_hz=nz.get("doppler_sigma_hz", float, 0.05, check=non_negative),
        dll_bandwidth_hz=nz.get("dll_bandwidth_hz", float, 1.0, check=positive),
        pll_bandwidth_hz=nz.get("pll_bandwidth_hz", float, 15.0, check=positive),
        fll_bandwidth_hz=nz.get("fll_bandwidth_hz", float, 2.0, check=positive),
        correlator_spacing_chips=nz.get("correlator_spacing_chips", float, 0.5, check=in_range(0.01, 1.0)),
        integration_time_s=nz.get("integration_time_s", float, 0.02, check=positive))
    nz.done()
    return cfg


def _multipath(mp: Section, sigs: list[str]) -> MultipathConfig:
    """[gnss.multipath], and [gnss.multipath.signal_correlation_time_s]: signal name -> correlation time (s) of
    that signal's multipath, where it differs from ``correlation_time_s`` (``simkit twin --fit`` estimates them)."""
    per = mp.section("signal_correlation_time_s")
    times = {name: per.get(name, float, None, check=positive) for name in sigs}
    per.done()
    cfg = MultipathConfig(
        code_sigma_m=mp.get("code_sigma_m", float, 1.0, check=non_negative),
        carrier_sigma_m=mp.get("carrier_sigma_m", float, 0.01, check=non_negative),
        elevation_scale_rad=np.radians(mp.get("elevation_scale_deg", float, 20.0, check=positive)),
        correlation_time_s=mp.get("correlation_time_s", float, 30.0, check=positive),
        signal_correlation_time_s={k: v for k, v in times.items() if v is not None})
    mp.done()
    return cfg


def _slip(s: Section, sigs: list[str], n_antennas: int) -> ScheduledSlip:
    sig = s.get("signal", str, None)
    if sig is not None and sig not in sigs:
        raise s.error("signal", f"must be one of gnss.signals {sigs!r}")
    ant = s.get("antenna", int, None, check=in_range(0, n_antennas - 1))
    cyc = s.get("cycles", int, None)
    if cyc == 0:
        raise s.error("cycles", "a slip must be a non-zero number of cycles")
    return ScheduledSlip(s.get("t_s", float, check=non_negative), s.get("sat", str, None), ant, sig, cyc)


def _outage(o: Section, n_antennas: int) -> Outage:
    start = o.get("start_s", float, check=non_negative)
    end = o.get("end_s", float, check=lambda v: None if v > start else "must be > start_s")
    sats = o.get("sats", str, None, shape=0)
    ants = o.get("antennas", int, None, shape=0)
    if ants is not None and any(not 0 <= a < n_antennas for a in ants):
        raise o.error("antennas", f"antenna indices must be in [0, {n_antennas - 1}]")
    return Outage(start, end, tuple(sats) if sats is not None else None, tuple(ants) if ants is not None else None)


def _code_scale(cs: Section, sigs: list[str]) -> dict:
    """[gnss.code_error_scale]: signal name -> factor (>= 0) on that signal's code noise and code multipath (a
    receiver's code tracking: correlator spacing, multipath mitigation; ``simkit twin --fit`` estimates them):
    a number, or a table ``{elevation_deg = [...], factor = [...]}`` (increasing elevations in [-90, 90],
    linear in between, the end values beyond), kept as the pair of tuples (elevation_deg, factor)."""
    return _per_signal(cs, sigs, "elevation_deg", (-90.0, 90.0), "factor", non_negative)


def _cn0_offset(cs: Section, sigs: list[str]) -> dict:
    """[gnss.cn0_offset_db]: signal name -> dB (in [-30, 30]) added to that signal's C/N0 offset of the signal
    table: the C/N0 a receiver reports differs by system and code beyond the received power (its correlator
    losses, its estimator; ``simkit twin --fit`` estimates them). A number, or a table ``{off_boresight_deg =
    [...], offset_db = [...]}`` (increasing angles in [0, 180], linear in between, the end values beyond), kept as
    the pair of tuples: a signal whose C/N0 falls with the angle faster than the antenna pattern says (the
    semi-codeless tracking of GPS L2 P(Y) loses more at low C/N0, and an antenna's gain differs by frequency)."""
    return _per_signal(cs, sigs, "off_boresight_deg", (0.0, 180.0), "offset_db", in_range(-30.0, 30.0))


def _per_signal(cs: Section, sigs: list[str], angle_key: str, bounds: tuple, value_key: str, check) -> dict:
    """A table keyed by signal name: each entry a number passing ``check``, or an angle table
    (:func:`_angle_table`); signals not given are left out."""
    out = {}
    for name in sigs:
        if isinstance(cs.data.get(name), dict):
            out[name] = _angle_table(cs.section(name), angle_key, bounds, value_key, check)
            continue
        value = cs.get(name, float, None, check=check)
        if value is not None:
            out[name] = value
    cs.done()
    return out


def _satellite_cn0_offset(cs: Section, sigs: list[str]) -> dict:
    """[gnss.satellite_cn0_offset_db.<signal>]: satellite id ("G01") -> dB (in [-30, 30]) added to that
    satellite's C/N0 of that signal: satellites transmit different powers (GPS blocks IIR, IIR-M, IIF and III
    differ by a few dB, on L2 most), and a static antenna sees each satellite along its own track
    (``simkit twin --fit`` estimates them at a fixed station)."""
    out = {}
    for name in sigs:
        if not cs.has(name):
            continue
        t = cs.section(name)
        table = {}
        for sat in list(t.data):
            if not (isinstance(sat, str) and len(sat) == 3 and sat[0] in "GCEJR" and sat[1:].isdigit()):
                raise t.error(str(sat), "expected a satellite id: a system letter and two digits (e.g. G01)")
            table[sat] = t.get(sat, float, check=in_range(-30.0, 30.0))
        t.done()
        out[name] = table
    cs.done()
    return out


def _angle_table(t: Section, angle_key: str, bounds: tuple, value_key: str, check) -> tuple:
    """A table of values against an angle (deg): (angles, values), the angles increasing within ``bounds``, one
    value per angle, each passing ``check`` (a Section check: None or the complaint)."""
    ang = t.get(angle_key, float, shape=0)
    vals = t.get(value_key, float, shape=0)
    if not ang or len(ang) != len(vals):
        raise t.error(value_key, f"expected one {value_key} per {angle_key} entry ({len(ang)}), got {len(vals)}")
    if any(b <= a for a, b in zip(ang, ang[1:])) or not all(bounds[0] <= a <= bounds[1] for a in ang):
        raise t.error(angle_key, f"expected increasing angles in [{bounds[0]:g}, {bounds[1]:g}], got {ang!r}")
    for v in vals:
        complaint = check(v)
        if complaint:
            raise t.error(value_key, f"{complaint}, got {vals!r}")
    t.done()
    return tuple(ang), tuple(vals)


def angle_table_at(scale, el_rad):
    """The value of a ``code_error_scale`` or ``cn0_offset_db`` entry (a number or an (angle_deg, value) pair) at
    the angles ``el_rad`` (rad, any shape: elevations for the first, off-boresight angles for the second)."""
    if not isinstance(scale, tuple):
        return scale
    return np.interp(np.degrees(el_rad), scale[0], scale[1])


def _ionosphere(io: Section) -> dict:
    iono = {}
    for system in ("gps", "bds"):
        a = io.get(f"{system}_alpha", float, None, shape=4)
        b = io.get(f"{system}_beta", float, None, shape=4)
        if (a is None) != (b is None):
            raise io.error(f"{system}_alpha" if a is None else f"{system}_beta",
                           f"give both {system}_alpha and {system}_beta")
        if a is not None:
            iono[system] = (tuple(a), tuple(b))
    io.done()
    return iono


def check_sats(cfg: GnssConfig, sat_ids) -> None:
    """Scheduled slips/outages must name satellites that exist in the loaded constellations."""
    known = set(sat_ids)
    for i, s in enumerate(cfg.slips):
        if s.sat is not None and s.sat not in known:
            raise ScenarioError(f"gnss.slip[{i}].sat", f"unknown satellite {s.sat!r}")
    for i, o in enumerate(cfg.outages):
        for s in o.sats or ():
            if s not in known:
                raise ScenarioError(f"gnss.outage[{i}].sats", f"unknown satellite {s!r}")
    for name, table in cfg.satellite_cn0_offset_db.items():
        for s in table:
            if s not in known:
                raise ScenarioError(f"gnss.satellite_cn0_offset_db.{name}.{s}",
                                    "unknown satellite: not in the scenario's constellations")
