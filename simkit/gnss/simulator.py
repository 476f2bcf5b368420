"""GnssSimulator: code, carrier, Doppler, C/N0 and LLI per antenna, satellite and signal, with every error term.

Observation equations (metres; per antenna a, satellite s, signal g with wavelength lambda_g; switches in
``gnss.errors``; rho the geometric range from the antenna phase centre at reception to the satellite at emission,
light time and Earth rotation included):

    code_g     = rho + c dt_a - c dT^s + c TGD_g^s + I_g + T + MP_code + eps_code
    carrier_g  = (rho + c dt_a - c dT^s - I_g + T + MP_carrier + eps_carrier) / lambda_g + N_g     [cycles]
    doppler_g  = -(rho' + c dt_a' - c dT^s' (1 - rho'/c) - I_g' + T') / lambda_g + eps_doppler    [Hz]

The stage is handed a :class:`simkit.constellation.Sky`; geometry comes from its light-time solution at the IMU
centre, refined to each antenna by :func:`simkit.constellation.antenna_view`. The rates of every term are exact
derivatives along the receiver's and the satellites' motion (troposphere: elevation and height; ionosphere:
pierce point, elevation, azimuth and time), so Doppler matches the time-differenced carrier at any dynamics.
:meth:`GnssSimulator.process` runs named steps (antennas, geometry, visibility, clocks, atmosphere, random draws
and multipath, tracking, assembly); the state carried between calls makes the output independent of the block
split.

By default (``gnss.truth_errors``, docs/truth_errors.md) rho is the range to the *true* satellite (the broadcast one
of ``/gnss/sat_pos_ecef`` plus an orbit error), dT^s the true clock, and I and T depart from the broadcast Klobuchar
and the Saastamoinen 1/sin(el) models that a receiver applies; each departure is stored in ``/gnss/truth``.
"""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Iterable, Iterator

import numpy as np

from .. import frames, gpstime, rng
from ..constellation import Sky, antenna_view, time_offsets
from ..constellation.antennas import AntennaView
from ..constellation.geometry import RECEPTION_GRID_S
from ..earth import C_LIGHT, EARTH_RATE_ECEF
from ..environment import DIRECT_REFLECTED, NLOS, Environment, LineOfSight
from ..errors import DataFileError, ScenarioError
from . import atmosphere, cn0_report, noise, signals as sigmod, tworay
from .acquisition import Acquisition
from .clock import ClockProcess
from .config import GnssConfig, check_sats, angle_table_at
from .draws import KeyedNormals
from .ephemeris_errors import EphemerisErrors
from .ionex import read_ionex
from .iono_steps import klobuchar_delays
from .iono_truth import TruthIonosphere
from .multipath import elevation_scale, multipath_bank
from .columns import consecutive, place_columns
from .orbit_range import range_errors
from .shadowing import BLOCKED, Shadowing
from .observables import GnssEpochs, GnssStatic, GnssTruth, SignalObs, SignalTruth
from .tracking import Tracking
from .tropo_truth import TruthTroposphere

_GD_NAMES = {"tgd": ("TGD",), "tgd1": ("TGD1",), "tgd2": ("TGD2",), "bgd_e5a": ("BGD_E5a",),
             "bgd_e5b": ("BGD_E5b",)}
_GD_PREFERRED = {"B1C": ("TGD_B1Cp",), "B2a": ("TGD_B2ap",)}
_MASK_MARGIN_RAD = 1e-3  # satellites this close below the mask at the IMU centre may be up at an antenna
_DEFAULT_KLOBUCHAR = {"G": (atmosphere.DEFAULT_GPS_ALPHA, atmosphere.DEFAULT_GPS_BETA),
                      "C": (atmosphere.DEFAULT_BDS_ALPHA, atmosphere.DEFAULT_BDS_BETA)}
# the broadcast ionosphere model each system's delays come from: Galileo, QZSS and GLONASS use the GPS
# Klobuchar model and coefficients, scaled from L1 to each carrier (one ionosphere for every line of sight)


@dataclass(frozen=True)
class BlockGeometry:
    """What :meth:`GnssSimulator.geometry` computes for a block of M epochs: times ``t`` (M,) s since the start
    and GPS ``week``/``sow`` (M,), antenna positions and velocities (M, A, 3) ECEF, the body-to-ECEF matrices
    ``c_be`` (M, 3, 3), the IMU centre's ``speed`` (M,) m/s, the light-time solution ``ref`` at the IMU centre
    (:meth:`simkit.constellation.Sky.view`), the candidate satellite columns ``cand`` (C,), their per-antenna
    ``view`` (:func:`simkit.constellation.antenna_view`) and the ``atmosphere`` along it."""

    t: np.ndarray
    week: np.ndarray
    sow: np.ndarray
    ant_pos: np.ndarray
    ant_vel: np.ndarray
    c_be: np.ndarray
    speed: np.ndarray
    ref: dict
    cand: np.ndarray
    view: AntennaView
    atmosphere: _Atmosphere


class GnssSimulator:
    """GNSS observables stage (see docs/gnss.md): ``cfg`` from :func:`simkit.gnss.parse_config`, ``sky`` the
    satellites, the scenario start in GPS time, the seed and the duration (s)."""

    def __init__(self, cfg: GnssConfig, sky: Sky, start_week: int, start_sow: float, seed: int,
                 duration_s: float, environment: Environment | None = None):
        self.cfg, self.sky, self.env = cfg, sky, environment
        self.start_week, self.start_sow = int(start_week), float(start_sow)
        self.duration_s = float(duration_s)
        self.dt = 1.0 / cfg.rate_hz
        self.sat_ids = list(sky.sat_ids)
        check_sats(cfg, self.sat_ids)
        self.system = np.array([s[0] for s in self.sat_ids])
        self.signals = [sigmod.get(n) for n in cfg.signals]
        prn = np.array([int(s[1:]) for s in self.sat_ids])
        # which satellites transmit each signal: the system's, and B1C/B2a only from BDS-3 (PRN >= 19)
        self.carries = np.array([(self.system == g.system) & ((g.name not in ("B1C", "B2a")) | (prn >= 19))
                                 for g in self.signals]).T  # (S, G)
        self.n_ant = len(cfg.antennas)
        self.lever = np.array([a.lever_arm_b for a in cfg.antennas])
        self.boresight = np.array([a.boresight_b for a in cfg.antennas])
        overrides = {"G": cfg.iono_coefficients.get("gps"), "C": cfg.iono_coefficients.get("bds")}
        self.iono = {k: overrides[k] or sky.klobuchar(k) or _DEFAULT_KLOBUCHAR[k] for k in "GC"}
        self.iono_model = np.array([atmosphere.model_system(x) for x in self.system], dtype="U1")
        # carrier frequency (S, G) Hz per satellite and signal: per FDMA channel for GLONASS
        channels = sky.channels
        self.freq = np.array([[g.frequency_for(channels[s]) if g.is_fdma else g.freq_hz for g in self.signals]
                              for s in range(len(self.sat_ids))], dtype=float).reshape(len(self.sat_ids), -1)
        self.group_delay_s = self._group_delays()
        # broadcast system time minus GPS time per simulated system (Galileo GGTO, QZSS, BDS fraction): a receiver
        # counting GPS time sees it in every range of that system's satellites (docs/systems.md)
        simulated = sorted(set(self.system[self.carries.any(axis=1)]))
        self.time_poly = time_offsets.polynomials(sky.time_offsets(), simulated) \
            if cfg.errors["system_time_offset"] else {}
        n_clk = self.n_ant if cfg.clock_mode == "per_antenna" else 1
        self.clocks = [ClockProcess(cfg.oscillator, self.dt, rng.generator(seed, "gnss", "clock",
                                                                            f"ant{a}" if n_clk > 1 else "common"))
                       for a in range(n_clk)]
        sys_signals = [np.flatnonzero([g.system == sys for g in self.signals]) for sys in self.system]
        self.draws = KeyedNormals(seed, self.n_ant, self.sat_ids, sys_signals, len(self.signals))
        self.cn0_draws = None if cfg.cn0_report is None else KeyedNormals(   # the receiver's C/N0 estimate
            seed, self.n_ant, self.sat_ids, sys_signals, len(self.signals), per_signal=1, stream=("gnss", "cn0_report"))
        taus = [cfg.multipath.signal_correlation_time_s.get(g.name, cfg.multipath.correlation_time_s)
                for g in self.signals]
        self.mp = multipath_bank(self.dt, np.array(taus)[:, None],
                                 (self.n_ant, len(self.sat_ids), len(self.signals), 2))
        self.tracking = Tracking(cfg, seed, self.sat_ids, self.n_ant)
        self.vis = np.zeros((self.n_ant, len(self.sat_ids)), dtype=bool)
        self.acquisition = Acquisition(cfg.acquisition, self.n_ant, len(self.sat_ids))
        self.nlos = np.zeros((self.n_ant, len(self.sat_ids)), dtype=bool)   # tracking a reflection only
        self.sat_index = {sid: k for k, sid in enumerate(self.sat_ids)}
        self.sat_cn0 = None      # (S, G) dB per satellite and signal, [gnss.satellite_cn0_offset_db]
        if cfg.satellite_cn0_offset_db:
            self.sat_cn0 = np.zeros((len(self.sat_ids), len(self.signals)))
            for j, name in enumerate(cfg.signals):
                for sid, db in cfg.satellite_cn0_offset_db.get(name, {}).items():
                    self.sat_cn0[self.sat_index[sid], j] = db
        self.shadowing = None if cfg.shadowing is None else Shadowing(cfg.shadowing, seed, self.sat_ids,
                                                                       self.n_ant, self.dt)
        self._truth_models(seed)

    def _truth_models(self, seed: int) -> None:
        """The truth-side departures from the receiver's models (``gnss.truth_errors``, docs/truth_errors.md);
        None where the truth equals the model."""
        te = self.cfg.truth_errors
        self.truth_iono = self.truth_tropo = self.ephemeris = None
        if te is None or not te.on:
            return
        ionex = None
        if te.ionex_file is not None:
            from pathlib import Path

            path = Path(te.ionex_file).expanduser()
            if not path.is_file():
                raise ScenarioError("gnss.truth_errors.ionex_file", f"{te.ionex_file}: no such file (expected an "
                                    "IONEX 1.0 file, plain or .gz)")
            ionex = read_ionex(path)
            end_w, end_s = gpstime.add_seconds(self.start_week, self.start_sow, self.duration_s)
            if not ionex.covers(np.array([self.start_week, end_w]), np.array([self.start_sow, end_s])):
                first = gpstime.gps_to_utc(ionex.first_week, ionex.first_sow)
                last = gpstime.gps_to_utc(*gpstime.add_seconds(ionex.first_week, ionex.first_sow, ionex.t_s[-1]))
                span = f"{first:%Y-%m-%d %H:%M} to {last:%Y-%m-%d %H:%M} UTC"
                raise ScenarioError("gnss.truth_errors.ionex_file", f"{te.ionex_file}: its TEC maps ({span}) do not "
                                    "cover the run (scenario.start, scenario.duration_s)")
        iono = TruthIonosphere(seed, te.iono_residual_fraction, te.iono_correlation_length_km * 1e3,
                               te.iono_correlation_time_s, ionex, te.iono_scale)
        self.truth_iono = iono if iono.departs else None
        tropo = TruthTroposphere(seed, self.start_week, self.start_sow, self.duration_s, te.tropo_mapping,
                                 te.tropo_zhd_sigma_m, te.tropo_zwd_sigma_m, te.tropo_zwd_random_walk_m_per_sqrt_h)
        self.truth_tropo = tropo if tropo.departs else None
        kinds = {sid: k for c in self.sky.constellations for sid, k in zip(c.sat_ids, c.orbit_type)}
        eph = EphemerisErrors(seed, self.sat_ids, te.ephemeris, [kinds.get(sid, "MEO") for sid in self.sat_ids])
        self.ephemeris = eph if eph.departs else None

    def _group_delays(self) -> np.ndarray:
        """Broadcast group delay (S, G) s per satellite and signal, records nearest the middle of the run."""
        mid_w, mid_s = gpstime.add_seconds(self.start_week, self.start_sow, 0.5 * self.duration_s)
        gds = self.sky.group_delays(mid_w, mid_s)
        out = np.zeros((len(self.sat_ids), len(self.signals)))
        for j, g in enumerate(self.signals):
            for name in _GD_PREFERRED.get(g.name, ()) + _GD_NAMES.get(g.tgd, ()):
                if name in gds:
                    fill = np.isfinite(gds[name]) & (out[:, j] == 0.0)
                    scale = g.tgd_scale if name in _GD_NAMES.get(g.tgd, ()) else 1.0
                    out[fill, j] = gds[name][fill] * scale
        out[~self.carries] = 0.0
        return out

    # ------------------------------------------------------------------ public contract
    def epoch_times(self) -> np.ndarray:
        """Receiver epochs, s since the scenario start, at ``gnss.rate_hz`` over [0, duration_s]."""
        n = int(np.floor(self.duration_s * self.cfg.rate_hz + 1e-9)) + 1
        return np.arange(n) * self.dt

    def static(self) -> GnssStatic:
        """The time-independent part of the output."""
        return GnssStatic(sat_id=np.array(self.sat_ids), signals=np.array(self.cfg.signals),
                          frequency_hz=np.array([g.freq_hz for g in self.signals]),
                          wavelength_m=np.array([g.wavelength_m for g in self.signals]),
                          sat_frequency_hz=self.freq,
                          group_delay=self.group_delay_s * C_LIGHT * self.cfg.errors["group_delay"],
                          lever_arm_b=self.lever, boresight_b=self.boresight, **self._klobuchar_rows(),
                          **self._time_offset_rows())

    def _time_offset_rows(self) -> dict[str, np.ndarray]:
        """The broadcast system-time offsets applied (none: no datasets, files stay as before)."""
        if not self.time_poly:
            return {}
        systems = sorted(self.time_poly)
        return {"time_offset_systems": np.array(systems, dtype="U1"),
                "time_offset": np.array([self.time_poly[k] for k in systems], dtype=float).reshape(-1, 4)}

    def _klobuchar_rows(self) -> dict[str, np.ndarray]:
        """The broadcast Klobuchar coefficients used, one row per simulated system with a model (G, C)."""
        systems = [k for k in self.iono if k in set(self.iono_model)]
        return {"iono_systems": np.array(systems, dtype="U1"),
                "iono_alpha": np.array([self.iono[k][0] for k in systems], dtype=float).reshape(-1, 4),
                "iono_beta": np.array([self.iono[k][1] for k in systems], dtype=float).reshape(-1, 4)}

    def process(self, t, pos_ecef, vel_ecef, quat_nb, omega_ib_b) -> GnssEpochs:
        """Observables at epochs ``t`` (M,) s (on the ``gnss.rate_hz`` grid, in order across calls) from the
        truth there: IMU-centre position (M, 3) m and velocity (M, 3) m/s in ECEF, attitude body->ENU (M, 4)
        scalar-last, body rate w.r.t. inertial space (M, 3) rad/s.

        Per-antenna work is done only for the satellites near or above the elevation mask (with an environment:
        above the horizon) at some epoch of the block (the candidate columns); the arrays are NaN elsewhere.
        """
        return self.observe(self.geometry(t, pos_ecef, vel_ecef, quat_nb, omega_ib_b))

    def process_blocks(self, blocks: Iterable[tuple], ahead: bool = True) -> Iterator[GnssEpochs]:
        """:meth:`process` of each block (t, pos_ecef, vel_ecef, quat_nb, omega_ib_b) of ``blocks``, in order.
        ``ahead``: the geometry of block k + 1 (:meth:`geometry`, which depends on that block's truth alone) is
        computed on a worker thread while block k's errors and observables are formed (the compiled passes
        release the GIL, so the two share two cores); the same arrays as :meth:`process`. ``blocks`` is iterated
        on the calling thread."""
        blocks = iter(blocks)
        if not ahead:
            for b in blocks:
                yield self.process(*b)
            return
        first = next(blocks, None)
        if first is None:
            return
        with ThreadPoolExecutor(max_workers=1, thread_name_prefix="simkit-gnss-geometry") as worker:
            pending = worker.submit(self.geometry, *first)
            while pending is not None:
                b = next(blocks, None)
                geo = pending.result()
                pending = worker.submit(self.geometry, *b) if b is not None else None
                yield self.observe(geo)

    def geometry(self, t, pos_ecef, vel_ecef, quat_nb, omega_ib_b) -> BlockGeometry:
        """The part of :meth:`process` that depends on the block's truth alone (no state carried between
        blocks, so blocks may run ahead): antenna positions, the light-time solution at the IMU centre, the
        candidate columns, the per-antenna view of them and the atmosphere along it."""
        t = np.asarray(t, dtype=float)
        pos = np.asarray(pos_ecef, dtype=float).reshape(t.size, 3)
        week, sow = gpstime.add_seconds(self.start_week, self.start_sow, t)
        ant_pos, ant_vel, c_be = frames.lever_arm_ecef(pos, np.asarray(vel_ecef, dtype=float).reshape(t.size, 3),
                                                       quat_nb, omega_ib_b, self.lever)
        ref = self.sky.view(pos, week, sow, reception_grid=self.cfg.rate_hz * RECEPTION_GRID_S >= 2.0)
        with np.errstate(invalid="ignore"):
            cand = np.flatnonzero((ref["elevation"] >= self._candidate_floor()).any(axis=0))
        view = antenna_view({k: v[:, cand] for k, v in ref.items()}, ant_pos, ant_vel)
        speed = np.linalg.norm(np.asarray(vel_ecef, dtype=float).reshape(t.size, 3), axis=1)
        return BlockGeometry(t, week, sow, ant_pos, ant_vel, c_be, speed, ref, cand, view,
                             _Atmosphere(self, t, week, sow, cand, view))

    def _candidate_floor(self) -> float:
        """The elevation (rad) at the IMU centre from which a satellite is a candidate column: the mask, or with an
        environment the horizon (a reflection can be tracked from below the mask), less the antennas' margin."""
        low = self.cfg.elevation_mask_rad if self.env is None else min(self.cfg.elevation_mask_rad, 0.0)
        return low - _MASK_MARGIN_RAD

    def observe(self, geo: BlockGeometry) -> GnssEpochs:
        """The rest of :meth:`process`, in block order (clocks, random draws, multipath and tracking carry their
        state from one block to the next): visibility, error terms and observables."""
        t, cand, view = geo.t, geo.cand, geo.view
        los = None
        if self.env is not None:
            los = self.env.classify(geo.ant_pos, view.lla, view.vel_enu, view.los, view.azimuth, view.elevation,
                                    view.azimuth_rate, view.elevation_rate, geo.c_be)
        vis_c, off = self._visibility(t, view, geo.c_be, cand, los)
        k0 = int(round(t[0] * self.cfg.rate_hz))
        shadow = None
        if self.shadowing is not None:   # street shadowing (simkit.gnss.shadowing): a blocked satellite is not tracked
            el_c = geo.ref["elevation"][:, cand]
            with np.errstate(invalid="ignore"):
                shadow = self.shadowing.advance(k0, el_c, el_c >= self._candidate_floor(),
                                                geo.speed, cand)
            vis_c = vis_c & (shadow.state != BLOCKED)
        vis_c = self.acquisition.apply(t, vis_c, view.elevation, cand)
        draws = self.draws.draw(k0, t.size, cand) * vis_c[..., None, None]
        cn0_z = None if self.cn0_draws is None else self.cn0_draws.draw(k0, t.size, cand)[..., 0]   # (M, A, C, G)
        parts = _Parts(self, t, geo.week, geo.sow, cand, view, vis_c, off, draws, geo.ref, geo.ant_vel,
                       geo.atmosphere, los, shadow, cn0_z)
        return GnssEpochs(t=t, sat_pos_ecef=geo.ref["sat_pos_emission"], sat_clock=geo.ref["sat_clock"],
                          truth=parts.truth(geo.ant_pos, geo.ant_vel), obs=parts.obs, signal_truth=parts.signal_truth)

    # ------------------------------------------------------------------ steps
    def _visibility(self, t, view, c_be, cand, los: LineOfSight | None = None):
        """Visible (M, A, C): above the elevation mask and the antenna's body-frame horizon, outside scheduled
        outages, not blocked by the environment; and the off-boresight angle (M, A, C) rad."""
        bore_e = np.einsum("mij,aj->mai", c_be, self.boresight)            # (M, A, 3)
        off = np.arccos(np.clip(np.einsum("maci,mai->mac", view.los, bore_e), -1.0, 1.0))
        horizon = np.array([x.horizon_mask_rad for x in self.cfg.antennas])
        vis = (np.isfinite(view.range) & (view.elevation >= self.cfg.elevation_mask_rad)
               & (np.pi / 2.0 - off >= horizon[None, :, None]))
        if los is not None:
            vis &= los.state <= NLOS
        for o in self.cfg.outages:
            rows = (t >= o.start_s) & (t < o.end_s)
            ants = np.zeros(self.n_ant, dtype=bool)
            ants[list(o.antennas) if o.antennas is not None else slice(None)] = True
            sats = np.zeros(len(self.sat_ids), dtype=bool)
            sats[[self.sat_index[x] for x in o.sats] if o.sats is not None else slice(None)] = True
            vis[rows] &= ~(ants[:, None] & sats[cand][None, :])
        return vis, off

    def receiver_clocks(self, m: int):
        """Receiver clock bias (M, A) s and drift (M, A) s/s over the next ``m`` epochs."""
        parts = [c.advance(m) for c in self.clocks]
        bias = np.stack([p[0] for p in parts], axis=1)
        drift = np.stack([p[1] for p in parts], axis=1)
        if bias.shape[1] == 1:
            bias, drift = np.repeat(bias, self.n_ant, axis=1), np.repeat(drift, self.n_ant, axis=1)
        return bias, drift

    def sigmas(self, cn0, g, wavelength_m=None):
        """Thermal-noise standard deviations (code m, carrier m, Doppler Hz) at C/N0 ``cn0`` dB-Hz (carrier
        wavelength ``wavelength_m``, broadcastable to ``cn0``; default the signal's)."""
        lam = g.wavelength_m if wavelength_m is None else wavelength_m
        nz = self.cfg.noise
        if nz.model == "constant":
            one = np.ones_like(cn0)
            return one * nz.code_sigma_m, one * nz.carrier_sigma_m, one * nz.doppler_sigma_hz
        return (noise.dll_sigma_m(cn0, g.chip_length_m, nz.dll_bandwidth_hz, nz.correlator_spacing_chips,
                                  nz.integration_time_s),
                noise.pll_sigma_m(cn0, lam, nz.pll_bandwidth_hz, nz.integration_time_s),
                noise.fll_sigma_hz(cn0, nz.fll_bandwidth_hz, nz.integration_time_s))


class _Atmosphere:
    """The troposphere and the ionosphere along the lines of sight of a block's candidate columns: elevation
    ``el`` (M, A, C) rad (kept above 1 mrad, zenith where unknown) and azimuth ``az``; ``trop``, ``trop_rate``,
    ``trop_error`` and ``iono``, ``iono_rate``, ``iono_error`` (M, A, C) m, m/s, m. Depends on the block's
    geometry alone (the truth models are fixed for the run), so it is computed with it."""

    def __init__(self, sim: GnssSimulator, t, week, sow, cand, view):
        self.sim, self.t, self.week, self.sow, self.cand, self.view = sim, t, week, sow, cand, view
        err = sim.cfg.errors
        self.el = np.where(np.isfinite(view.elevation), np.maximum(view.elevation, 1e-3), np.pi / 2)
        self.az = np.where(np.isfinite(view.azimuth), view.azimuth, 0.0)
        self._troposphere(err)
        self._ionosphere(err)

    def _troposphere(self, err):
        """Slant delay (M, A, C) m, its rate and the truth minus the receiver's model."""
        view = self.view
        lat, hgt = view.lla[..., 0, None], view.lla[..., 2, None]
        self.trop_error = np.zeros(self.el.shape)
        if err["troposphere"] and self.sim.truth_tropo is not None:
            self.trop, self.trop_rate, model = self.sim.truth_tropo.slant(
                lat, hgt, self.el, view.vel_enu[..., 2, None], view.elevation_rate, self.t[:, None, None])
            self.trop_error = self.trop - model
        elif err["troposphere"]:
            self.trop = atmosphere.troposphere(lat, hgt, self.el)
            self.trop_rate = atmosphere.troposphere_rate(lat, hgt, self.el, view.vel_enu[..., 2, None],
                                                         view.elevation_rate)
        else:
            self.trop = self.trop_rate = np.zeros(self.el.shape)

    def _ionosphere(self, err):
        """Delay (M, A, C) m at each model's reference frequency (L1 for GPS, Galileo, QZSS, GLONASS; B1I for
        BDS), its rate, and the truth minus the broadcast model.

        A truth that departs from the broadcast model is evaluated along the first antenna's lines of sight and
        shared by every antenna of the vehicle: antennas metres apart see a satellite within a microradian of each
        other, through pierce points metres apart on fields that vary over hundreds of kilometres (Klobuchar, the
        truth's random field, a map's 2.5 deg cells), so their delays differ by tens of micrometres (at most
        3.4e-5 m, near the horizon on B3I, on xian_static_bds's 9.4 m baseline: ``benchmarks/gnss_ab.py``), a
        fiftieth of the carrier noise. The broadcast model, which a receiver evaluates at its own antenna, is taken
        per antenna, so that truth minus the stored model error is exactly the receiver's correction."""
        self.iono = np.zeros(self.el.shape)
        self.iono_rate = np.zeros(self.el.shape)
        self.iono_error = np.zeros(self.el.shape)
        if not err["ionosphere"]:
            return
        view, system, truth = self.view, self.sim.iono_model[self.cand], self.sim.truth_iono
        sow = self.sow[:, None, None]
        first = slice(0, 1)
        for letter in "GC":
            cols = system == letter
            if not cols.any():
                continue
            alpha, beta = self.sim.iono[letter]
            if truth is None:
                self.iono[..., cols], self.iono_rate[..., cols] = atmosphere.ionosphere(
                    letter, alpha, beta, view.lla, view.vel_enu, self.az[..., cols], self.el[..., cols],
                    view.azimuth_rate[..., cols], view.elevation_rate[..., cols], sow)
                continue
            iono, rate, klob = truth.delay(
                letter, alpha, beta, view.lla[:, first], view.vel_enu[:, first], self.az[:, first][..., cols],
                self.el[:, first][..., cols], view.azimuth_rate[:, first][..., cols],
                view.elevation_rate[:, first][..., cols], self.week[:, None, None], sow, self.t[:, None, None])
            seen = np.isfinite(view.range[:, first][..., cols])
            if not np.all(np.isfinite(iono)[seen]):
                raise DataFileError(truth.ionex.path, "the TEC maps have no value at a pierce point of the run "
                                    "(a regional map, or missing values)")
            if self.sim.n_ant > 1:
                others = slice(1, None)
                klob = np.concatenate([klob, klobuchar_delays(
                    letter, alpha, beta, view.lla[:, others, 0], view.lla[:, others, 1],
                    self.az[:, others][..., cols], self.el[:, others][..., cols], self.sow)], axis=1)
            self.iono[..., cols], self.iono_rate[..., cols] = iono, rate
            self.iono_error[..., cols] = iono - klob


class _Parts:
    """The error terms and observables of one block, computed step by step on the candidate columns."""

    def __init__(self, sim: GnssSimulator, t, week, sow, cand, view, vis_c, off, draws, ref, ant_vel, atmo, los=None,
                 shadow=None, cn0_z=None):
        self.sim, self.cand, self.view, self.m, self.los, self.shadow = sim, cand, view, t.size, los, shadow
        self.cn0_z = cn0_z
        self.t, self.week, self.sow = t, week, sow
        self.shape = (t.size, sim.n_ant, len(sim.sat_ids))
        err = sim.cfg.errors
        vis = self.full(vis_c, False)
        tracked = vis[..., None] & sim.carries[None, None, :, :]            # (M, A, S, G)
        prev_vis = np.concatenate([sim.vis[None], vis[:-1]], axis=0)
        restart = (vis & ~prev_vis)[..., cand]
        sim.vis = vis[-1].copy()
        reacquire = None
        if los is not None:  # a loop switching between the direct signal and a reflection loses lock
            nlos = self.full(los.state == NLOS, False)
            switch = vis & prev_vis & (nlos != np.concatenate([sim.nlos[None], nlos[:-1]], axis=0))
            sim.nlos = nlos[-1].copy()
            reacquire = switch[..., None] & sim.carries[None, None, :, :]
        self._clocks(err)
        self._ephemeris(err, ref, ant_vel)
        self.el, self.az = atmo.el, atmo.az
        self.trop, self.trop_rate, self.trop_error = atmo.trop, atmo.trop_rate, atmo.trop_error
        self.iono, self.iono_rate, self.iono_error = atmo.iono, atmo.iono_rate, atmo.iono_error
        self.mp = sim.mp.advance(draws[..., 3:5], restart, index=(slice(None), cand)) if err["multipath"] else None
        amb, lli = sim.tracking.advance(t, tracked, reacquire)
        self.obs, self.signal_truth = {}, {}
        for j, g in enumerate(sim.signals):
            self._signal(j, g, off, draws, tracked, amb, lli)

    def full(self, x, fill=np.nan):
        """(M, A, S) array with the candidate columns ``x`` and ``fill`` elsewhere."""
        if np.asarray(x).dtype == np.float64:
            return place_columns(x, self.cand, self.shape[2], fill=fill)
        out = np.full(self.shape, fill, dtype=np.asarray(x).dtype)
        out[..., self.cand] = x
        return out

    def _clocks(self, err):
        sim, view = self.sim, self.view
        dtr, ddtr = sim.receiver_clocks(self.m)                                      # (M, A)
        self.rx_clk = C_LIGHT * dtr * err["receiver_clock"]
        self.rx_clk_rate = C_LIGHT * ddtr * err["receiver_clock"]
        self.sat_clk = -C_LIGHT * np.nan_to_num(view.sat_clock) * err["satellite_clock"]
        self.sat_clk_rate = (-C_LIGHT * np.nan_to_num(view.sat_drift) * (1.0 - view.range_rate / C_LIGHT)
                             * err["satellite_clock"])
        self.sys_offset = None
        if sim.time_poly:  # the satellite clock against GPS time: its broadcast clock plus its system's offset
            off, off_rate = time_offsets.evaluate(sim.time_poly, sim.system, self.week, self.sow)   # (M, S)
            self.sys_offset = -C_LIGHT * off                                                        # (M, S) m
            self.sat_clk = self.sat_clk + self.sys_offset[:, None, self.cand]
            self.sat_clk_rate = self.sat_clk_rate - (C_LIGHT * off_rate[:, None, self.cand]
                                                     * (1.0 - view.range_rate / C_LIGHT))
        self.clk = self.rx_clk[..., None] + self.sat_clk
        self.clk_rate = self.rx_clk_rate[..., None] + self.sat_clk_rate

    def _ephemeris(self, err, ref, ant_vel):
        """Broadcast orbit and clock errors: the true range differs from the range to the broadcast satellite by
        ``orb`` (M, A, C) m, the true clock term by ``sat_clk_error`` (M, S) m (see ephemeris_errors)."""
        sim, view, cand = self.sim, self.view, self.cand
        n_sat = len(sim.sat_ids)
        self.orbit_rac = np.zeros((self.m, n_sat, 3))
        self.sat_clk_error = np.zeros((self.m, n_sat))
        self.orb = self.orb_rate = np.zeros(view.range.shape)
        self.range, self.range_rate = view.range, view.range_rate
        if sim.ephemeris is None:
            return
        e, e_rate = sim.ephemeris.at(self.week, self.sow, np.arange(n_sat))           # (M, S, 4)
        known = np.isfinite(ref["sat_pos"]).all(axis=-1)
        self.orbit_rac = np.where(known[..., None], e[..., :3], np.nan)
        on = err["satellite_clock"]
        self.sat_clk_error = np.where(known, -e[..., 3] * on, np.nan)
        self.sat_clk = self.sat_clk - e[:, None, cand, 3] * on
        self.sat_clk_rate = self.sat_clk_rate - e_rate[:, None, cand, 3] * (1.0 - view.range_rate / C_LIGHT) * on
        self.clk = self.rx_clk[..., None] + self.sat_clk
        self.clk_rate = self.rx_clk_rate[..., None] + self.sat_clk_rate
        pos, vel = np.nan_to_num(ref["sat_pos"][:, cand]), np.nan_to_num(ref["sat_vel"][:, cand])
        v_in = vel + np.cross(EARTH_RATE_ECEF, pos)
        rel = vel[:, None] - ant_vel[:, :, None]          # d(satellite - antenna)/dt in the rotating frame
        rac, rac_rate = e[:, cand, :3], e_rate[:, cand, :3]
        h = 0.5
        orb = range_errors(view.los, view.range, rel, pos, vel, v_in, rac, rac_rate, np.array([0.0, h, -h]))
        self.orb = orb[0]
        self.orb_rate = (orb[1] - orb[2]) / (2.0 * h)
        self.range, self.range_rate = view.range + self.orb, view.range_rate + self.orb_rate

    def _cn0(self, j, g, off, cols):
        """True C/N0 (dB-Hz) of signal ``g`` (index ``j``) at the off-boresight angles ``off`` (M, A, C) rad of the
        satellite columns ``cols``: zenith, the antenna's rolloff or gain pattern, the signal's offset (a table by
        the angle where given), each satellite's own offset; street shadowing comes after."""
        cfg = self.sim.cfg
        rolloff = np.array([x.rolloff_db for x in cfg.antennas])[None, :, None]
        cn0_off = g.cn0_offset_db + angle_table_at(cfg.cn0_offset_db.get(g.name, 0.0), off)
        cn0 = noise.cn0_dbhz(off, cfg.cn0_zenith_dbhz, rolloff, cn0_off)
        for a, ant in enumerate(cfg.antennas):
            if ant.gain_pattern is not None:
                cn0[:, a] = noise.pattern_cn0_dbhz(off[:, a], cfg.cn0_zenith_dbhz, ant.gain_pattern,
                                                   cn0_off[:, a] if np.ndim(cn0_off) else cn0_off)
        if self.sim.sat_cn0 is not None:
            cn0 = cn0 + self.sim.sat_cn0[cols, j]
        return cn0

    def _signal(self, j, g, off, draws, tracked, amb, lli):
        """Observables and error terms of signal ``g`` (index ``j``) on the columns that transmit it."""
        sim, cfg, err = self.sim, self.sim.cfg, self.sim.cfg.errors
        cj = np.flatnonzero(sim.carries[self.cand, j])
        cols = self.cand[cj]
        cj = consecutive(cj)   # one system's columns: views, not copies
        cn0 = self._cn0(j, g, off[..., cj], cols)
        if self.shadow is not None:
            cn0 = cn0 - self.shadow.attenuation_db[..., cj]
        freq = sim.freq[cols, j]                                                    # (C,) Hz
        lam = C_LIGHT / freq if g.is_fdma else g.wavelength_m
        sig_c, sig_p, sig_d = (s * err["noise"] for s in sim.sigmas(cn0, g, lam))
        scale = (atmosphere.reference_frequency(g.system) / freq) ** 2
        iono, iono_rate = self.iono[..., cj] * scale, self.iono_rate[..., cj] * scale
        el = self.el[..., cj]
        code_scale = angle_table_at(cfg.code_error_scale.get(g.name, 1.0), el)
        sig_c = sig_c * code_scale
        if self.mp is not None:
            mp_c = elevation_scale(el, cfg.multipath.code_sigma_m * code_scale, cfg.multipath.elevation_scale_rad) * \
                self.mp[:, :, cj, j, 0]
            mp_p = elevation_scale(el, cfg.multipath.carrier_sigma_m, cfg.multipath.elevation_scale_rad) * \
                self.mp[:, :, cj, j, 1]
        else:
            mp_c = mp_p = np.zeros(cn0.shape)
        mp_rate = None
        if self.los is not None:
            cn0, mp_c, mp_p, mp_rate = self._environment(cj, g, cn0, mp_c, mp_p)
            sig_c, sig_p, sig_d = (s * err["noise"] for s in sim.sigmas(cn0, g, lam))
            sig_c = sig_c * code_scale
        n_c, n_p, n_d = (draws[:, :, cj, j, i] * s for i, s in enumerate((sig_c, sig_p, sig_d)))
        gd = C_LIGHT * sim.group_delay_s[cols, j] * err["group_delay"]
        base = self.range[..., cj] + self.clk[..., cj] + self.trop[..., cj]
        rate = self.range_rate[..., cj] + self.clk_rate[..., cj] + self.trop_rate[..., cj]
        keep = tracked[..., cols, j]

        def put(x, masked=False):
            return place_columns(x, cols, self.shape[2], keep if masked else None)

        report = cfg.cn0_report
        cn0_out = cn0 if report is None else cn0_report.reported(cn0, self.cn0_z[..., cj, j], report)

        self.obs[g.name] = SignalObs(
            code=put(base + gd + iono + mp_c + n_c, True),
            carrier=put((base - iono + mp_p + n_p) / lam + amb[..., cols, j], True),
            doppler=put(-(rate - iono_rate + (0.0 if mp_rate is None else mp_rate)) / lam + n_d, True),
            cn0=put(cn0_out, True),
            ambiguity=amb[..., j], lli=lli[..., j])
        self.signal_truth[g.name] = SignalTruth(
            ionosphere=put(iono), ionosphere_rate=put(iono_rate), multipath_code=put(mp_c),
            multipath_carrier=put(mp_p), noise_code=put(n_c), noise_carrier=put(n_p), noise_doppler=put(n_d),
            sigma_code=put(sig_c), sigma_carrier=put(sig_p), sigma_doppler=put(sig_d),
            multipath_rate=None if mp_rate is None else put(mp_rate),
            cn0=None if report is None else put(cn0, True))

    def _environment(self, cj, g, cn0, mp_c, mp_p):
        """C/N0 and multipath of signal ``g`` on columns ``cj`` under the environment: a direct signal plus a
        reflection gets the two-ray errors (:mod:`simkit.gnss.tworay`) instead of the statistical multipath, a
        reflection alone (NLOS) carries its extra path on code and carrier and loses the reflection loss;
        returns C/N0, code and carrier multipath (m) and the carrier multipath rate (m/s)."""
        cfg = self.sim.env.cfg
        st, ex, ex_rate = self.los.state[..., cj], self.los.extra[..., cj], self.los.extra_rate[..., cj]
        alpha = 10.0 ** (-cfg.reflection_loss_db / 20.0)
        two, nl = st == DIRECT_REFLECTED, st == NLOS
        lam = g.wavelength_m
        theta = 2.0 * np.pi * ex[two] / lam + np.pi
        theta_rate = 2.0 * np.pi * ex_rate[two] / lam
        code_two = tworay.dll_error_chips(alpha, ex[two] / g.chip_length_m, theta,
                                          self.sim.cfg.noise.correlator_spacing_chips) * g.chip_length_m
        cn0, mp_c, mp_p = cn0.copy(), mp_c.copy(), mp_p.copy()
        rate = np.zeros(cn0.shape)
        cn0[two] += tworay.amplitude_gain_db(alpha, theta)
        cn0[nl] -= cfg.reflection_loss_db
        mp_c[two] = code_two
        mp_p[two] = tworay.carrier_phase_error(alpha, theta) * lam / (2.0 * np.pi)
        rate[two] = tworay.carrier_phase_error_rate(alpha, theta, theta_rate) * lam / (2.0 * np.pi)
        mp_c[nl] = mp_p[nl] = ex[nl]
        rate[nl] = ex_rate[nl]
        return cn0, mp_c, mp_p, rate

    def truth(self, ant_pos, ant_vel) -> GnssTruth:
        v = self.view
        return GnssTruth(antenna_pos_ecef=ant_pos, antenna_vel_ecef=ant_vel, range=self.full(self.range),
                         range_rate=self.full(self.range_rate), elevation=self.full(v.elevation),
                         azimuth=self.full(v.azimuth), receiver_clock=self.rx_clk,
                         receiver_clock_drift=self.rx_clk_rate, satellite_clock=self.full(self.sat_clk),
                         satellite_clock_drift=self.full(self.sat_clk_rate), troposphere=self.full(self.trop),
                         troposphere_rate=self.full(self.trop_rate),
                         ionosphere_model_error=self.full(self.iono_error),
                         troposphere_model_error=self.full(self.trop_error),
                         orbit_range_error=self.full(self.orb), orbit_error_rac=self.orbit_rac,
                         satellite_clock_error=self.sat_clk_error,
                         system_time_offset=self.sys_offset,
                         los_state=None if self.los is None else self.full(self.los.state, 255),
                         nlos_delay=None if self.los is None else self.full(self.los.extra),
                         shadow_state=None if self.shadow is None else self.full(self.shadow.state, 255),
                         shadow_attenuation=None if self.shadow is None else self.full(
                             np.where(self.shadow.state <= 1, self.shadow.attenuation_db, np.nan)))
