"""GnssSimulator: code, carrier, Doppler, C/N0 and LLI per antenna, satellite and signal, with every error term.

Observation equations (metres; per antenna a, satellite s, signal g with wavelength lambda_g; switches in
``gnss.errors``; rho the geometric range from the antenna phase centre at reception to the satellite at emission,
light time and Earth rotation included):

    code_g     = rho + c dt_a - c dT^s + c TGD_g^s + I_g + T + MP_code + eps_code
    carrier_g  = (rho + c dt_a - c dT^s - I_g + T + MP_carrier + eps_carrier) / lambda_g + N_g     [cycles]
    doppler_g  = -(rho' + c dt_a' - c dT^s' (1 - rho'/c) - I_g' + T') / lambda_g + eps_doppler    [Hz]

Geometry comes from :func:`simkit.constellation.receiver_view` (light-time iteration with Earth rotation) at the
IMU centre; each antenna's emission time then follows from the satellite's inertial motion over the few
nanoseconds of extra light time (X(t - tau0 - d) = X0 - V d, error below 1e-12 m for baselines of tens of m).
The range rate is the exact derivative of the light-time range in the inertial frame aligned with ECEF at
reception: rho' = u.(V_s - V_r) / (1 + u.V_s / c), so Doppler matches the time-differenced carrier at any
dynamics (no linearisation across epochs). The state carried between calls to :meth:`process` (clocks,
multipath, ambiguities, slip times, tracking) makes the output independent of the block split.
"""
from __future__ import annotations

import heapq

import numpy as np
from scipy.spatial.transform import Rotation

from .. import frames, gpstime, rng
from ..constellation import load, receiver_view
from ..constellation.geometry import elevation_azimuth
from ..earth import C_LIGHT, OMEGA_E
from ..errors import DataFileError, ScenarioError
from . import atmosphere, noise, signals as sigmod
from .clock import ClockProcess
from .config import GnssConfig, check_sats
from .multipath import GaussMarkov, elevation_scale

LLI_LOSS_OF_LOCK = 1  # RINEX LLI bit 0: lost lock since the previous observation, a cycle slip is possible
_OMEGA = np.array([0.0, 0.0, OMEGA_E])
_GD_NAMES = {"tgd": ("TGD",), "tgd1": ("TGD1",), "tgd2": ("TGD2",)}
_GD_PREFERRED = {"B1C": ("TGD_B1Cp",), "B2a": ("TGD_B2ap",)}


class _Sky:
    """Several constellations seen as one satellite list."""

    def __init__(self, sources):
        self.consts = []
        for i, src in enumerate(sources):
            try:
                self.consts.append(load(src))
            except DataFileError as exc:  # it names the file; say which scenario key gave it
                raise ScenarioError(f"gnss.constellation[{i}].source", str(exc)) from exc
        self.sat_ids = [s for c in self.consts for s in c.sat_ids]
        if len(set(self.sat_ids)) != len(self.sat_ids):
            dup = sorted({s for s in self.sat_ids if self.sat_ids.count(s) > 1})
            raise ScenarioError("gnss.constellation", f"satellites loaded twice: {', '.join(dup)}")

    def view(self, rx, week, sow):
        parts = []
        for c in self.consts:
            parts.append(receiver_view(c, rx, week, sow, velocity=True))
        cat = lambda name: np.concatenate([getattr(p, name) for p in parts], axis=1)  # noqa: E731
        return {k: cat(k) for k in ("sat_pos", "sat_vel", "sat_clock", "sat_drift", "tau", "elevation")}

    def klobuchar(self, system):
        for c in self.consts:
            k = getattr(c, "klobuchar", {}).get(system)
            if k is not None:
                return tuple(k.alpha), tuple(k.beta)
        return None

    def group_delays(self, week, sow) -> dict[str, np.ndarray]:
        """Broadcast group delays per name -> (S,) s (NaN where absent), nearest to (week, sow)."""
        out: dict[str, list] = {}
        offset = 0
        total = len(self.sat_ids)
        for c in self.consts:
            n = len(c.sat_ids)
            gd = c.group_delays(week, sow) if hasattr(c, "group_delays") else {}
            for name, vals in gd.items():
                out.setdefault(name, np.full(total, np.nan))[offset:offset + n] = vals
            offset += n
        return out


class GnssSimulator:
    """GNSS observables stage (see docs/gnss.md). ``cfg`` from :func:`simkit.gnss.parse_config`."""

    def __init__(self, cfg: GnssConfig, start_week: int, start_sow: float, seed: int, duration_s: float):
        self.cfg = cfg
        self.start_week, self.start_sow = int(start_week), float(start_sow)
        self.seed = int(seed)
        self.duration_s = float(duration_s)
        self.dt = 1.0 / cfg.rate_hz
        self.sky = _Sky(cfg.sources)
        self.sat_ids = self.sky.sat_ids
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
        self.iono = {
            "G": cfg.iono_coefficients.get("gps") or self.sky.klobuchar("G")
            or (atmosphere.DEFAULT_GPS_ALPHA, atmosphere.DEFAULT_GPS_BETA),
            "C": cfg.iono_coefficients.get("bds") or self.sky.klobuchar("C")
            or (atmosphere.DEFAULT_BDS_ALPHA, atmosphere.DEFAULT_BDS_BETA),
        }
        mid_w, mid_s = gpstime.add_seconds(self.start_week, self.start_sow, 0.5 * self.duration_s)
        gds = self.sky.group_delays(mid_w, mid_s)
        self.group_delay_s = np.zeros((len(self.sat_ids), len(self.signals)))
        for j, g in enumerate(self.signals):
            for name in _GD_PREFERRED.get(g.name, ()) + _GD_NAMES.get(g.tgd, ()):
                if name in gds:
                    vals = gds[name]
                    fill = np.isfinite(vals) & (self.group_delay_s[:, j] == 0.0)
                    self.group_delay_s[fill, j] = vals[fill] * (g.tgd_scale if name in _GD_NAMES.get(g.tgd, ())
                                                                else 1.0)
        self.group_delay_s[~self.carries] = 0.0

        n_clk = self.n_ant if cfg.clock_mode == "per_antenna" else 1
        self.clocks = [ClockProcess(cfg.oscillator, self.dt, rng.generator(seed, "gnss", "clock",
                                                                            f"ant{a}" if n_clk > 1 else "common"))
                       for a in range(n_clk)]
        s, g = len(self.sat_ids), len(self.signals)
        self.noise_rng = [[rng.generator(seed, "gnss", f"ant{a}", sid) for sid in self.sat_ids]
                          for a in range(self.n_ant)]
        self.event_rng = [[rng.generator(seed, "gnss", f"ant{a}", sid, "events") for sid in self.sat_ids]
                          for a in range(self.n_ant)]
        self.sys_signals = [np.flatnonzero([sg.system == sys for sg in self.signals]) for sys in self.system]
        self.mp = GaussMarkov(self.dt, cfg.multipath.correlation_time_s, (self.n_ant, s, g, 2))
        self.vis = np.zeros((self.n_ant, s), dtype=bool)
        self.tracked = np.zeros((self.n_ant, s, g), dtype=bool)
        self.amb = np.zeros((self.n_ant, s, g), dtype=np.int64)
        rate = cfg.slip_rate_per_h / 3600.0
        self.next_slip = np.full((self.n_ant, s, g), np.inf)
        if cfg.errors["cycle_slips"] and rate > 0:
            for a in range(self.n_ant):
                for k in range(s):
                    self.next_slip[a, k] = self.event_rng[a][k].exponential(1.0 / rate, g)
        self.slip_rate = rate
        self.t_last = -np.inf
        self.sat_index = {sid: k for k, sid in enumerate(self.sat_ids)}
        self.sig_index = {n: j for j, n in enumerate(cfg.signals)}

    # ------------------------------------------------------------------ public contract
    def epoch_times(self) -> np.ndarray:
        """Receiver epochs, s since the scenario start, at ``gnss.rate_hz`` over [0, duration_s]."""
        n = int(np.floor(self.duration_s * self.cfg.rate_hz + 1e-9)) + 1
        return np.arange(n) * self.dt

    def static_datasets(self) -> dict:
        """Time-independent datasets: relative path under /gnss -> (array, units)."""
        return {
            "sat_id": (np.array(self.sat_ids), ""),
            "signals": (np.array(self.cfg.signals), ""),
            "frequency_hz": (np.array([g.freq_hz for g in self.signals]), "Hz"),
            "wavelength_m": (np.array([g.wavelength_m for g in self.signals]), "m"),
            "group_delay": (self.group_delay_s * C_LIGHT * self.cfg.errors["group_delay"], "m"),
            "antennas/lever_arm_b": (self.lever, "m"),
            "antennas/boresight_b": (self.boresight, ""),
        }

    def process(self, t, pos_ecef, vel_ecef, quat_nb, omega_ib_b) -> dict:
        """Observables at epochs ``t`` (M,) s from the truth there (IMU centre, ECEF; body->ENU attitude;
        body rate w.r.t. inertial space). Returns relative path under /gnss -> (array, units).

        Per-antenna work is done only for the satellites above the elevation mask at some epoch of the block
        (the "candidate" columns); arrays are NaN elsewhere.
        """
        t = np.asarray(t, dtype=float)
        m = t.size
        cfg, err = self.cfg, self.cfg.errors
        pos = np.asarray(pos_ecef, dtype=float).reshape(m, 3)
        vel = np.asarray(vel_ecef, dtype=float).reshape(m, 3)
        week, sow = gpstime.add_seconds(self.start_week, self.start_sow, t)
        s_count, a_count = len(self.sat_ids), self.n_ant

        ant_pos, ant_vel, c_be = self._antennas(pos, vel, quat_nb, omega_ib_b)
        ref = self.sky.view(pos, week, sow)
        with np.errstate(invalid="ignore"):
            cand = np.flatnonzero((ref["elevation"] >= cfg.elevation_mask_rad - 1e-3).any(axis=0))
        geo = self._antenna_geometry({k: v[:, cand] for k, v in ref.items()}, ant_pos, ant_vel)

        def full(x, fill=np.nan):
            out = np.full((m, a_count, s_count), fill, dtype=np.asarray(x).dtype)
            out[..., cand] = x
            return out

        # --- visibility: elevation mask, body-frame horizon of each antenna, scheduled outages
        bore_e = np.einsum("mij,aj->mai", c_be, self.boresight)            # (M, A, 3)
        off = np.arccos(np.clip(np.einsum("maci,mai->mac", geo["los"], bore_e), -1.0, 1.0))
        horizon = np.array([x.horizon_mask_rad for x in cfg.antennas])
        vis_c = (np.isfinite(geo["range"]) & (geo["el"] >= cfg.elevation_mask_rad)
                 & (np.pi / 2.0 - off >= horizon[None, :, None]))
        for o in cfg.outages:
            rows = (t >= o.start_s) & (t < o.end_s)
            ants = np.zeros(a_count, dtype=bool)
            ants[list(o.antennas) if o.antennas is not None else slice(None)] = True
            sats = np.zeros(s_count, dtype=bool)
            sats[[self.sat_index[x] for x in o.sats] if o.sats is not None else slice(None)] = True
            vis_c[rows] &= ~(ants[:, None] & sats[cand][None, :])
        vis = full(vis_c, False)
        tracked = vis[..., None] & self.carries[None, None, :, :]         # (M, A, S, G)
        prev_vis = np.concatenate([self.vis[None], vis[:-1]], axis=0)
        restart = (vis & ~prev_vis)[..., cand]                             # (re)acquisitions, (M, A, C)
        self.vis = vis[-1].copy()

        # --- clocks (receiver per antenna or common; satellite at each antenna's emission time)
        dtr, ddtr = self._clock(m)                                          # (M, A)
        rr = geo["range_rate"]
        rx_clk = C_LIGHT * dtr * err["receiver_clock"]
        rx_clk_rate = C_LIGHT * ddtr * err["receiver_clock"]
        sat_clk = -C_LIGHT * np.nan_to_num(geo["sat_clock"]) * err["satellite_clock"]
        sat_clk_rate = -C_LIGHT * np.nan_to_num(geo["sat_drift"]) * (1.0 - rr / C_LIGHT) * err["satellite_clock"]
        clk = rx_clk[..., None] + sat_clk
        clk_rate = rx_clk_rate[..., None] + sat_clk_rate

        # --- troposphere and its rate
        lla = frames.ecef_to_lla(ant_pos.reshape(-1, 3)).reshape(ant_pos.shape)  # (M, A, 3)
        lat, lon, hgt = lla[..., 0, None], lla[..., 1, None], lla[..., 2, None]
        el_safe = np.where(np.isfinite(geo["el"]), np.maximum(geo["el"], 1e-3), np.pi / 2)
        az_safe = np.where(np.isfinite(geo["az"]), geo["az"], 0.0)
        if err["troposphere"]:
            zh, zw = atmosphere.saastamoinen_zenith(lat, hgt)
            trop = (zh + zw) / np.sin(el_safe)
            trop_rate = -(zh + zw) * np.cos(el_safe) / np.sin(el_safe) ** 2 * geo["el_rate"]
        else:
            trop = trop_rate = np.zeros(el_safe.shape)

        # --- ionosphere (per-system broadcast model at its reference frequency) and its rate (difference over
        # 0.5 s along the line-of-sight motion: the delay's curvature makes that < 1e-6 m/s)
        iono_ref = np.zeros(el_safe.shape)
        iono_ref_rate = np.zeros(el_safe.shape)
        if err["ionosphere"]:
            h = 0.5
            tow = sow[:, None, None]
            for letter, model, shift in (("G", atmosphere.klobuchar_gps, 0.0),
                                         ("C", atmosphere.klobuchar_bds, gpstime.BDT_MINUS_GPST)):
                cols = self.system[cand] == letter
                if not cols.any():
                    continue
                alpha, beta = self.iono[letter]
                e, az = el_safe[..., cols], az_safe[..., cols]
                er, ar = geo["el_rate"][..., cols], geo["az_rate"][..., cols]
                iono_ref[..., cols] = model(alpha, beta, lat, lon, az, e, tow + shift)
                up = model(alpha, beta, lat, lon, az + ar * h, e + er * h, tow + shift + h)
                iono_ref_rate[..., cols] = (up - iono_ref[..., cols]) / h

        # --- random parts
        draws = self._draws(vis_c, cand)                                    # (M, A, C, G, 5)
        mpx = self.mp.advance(draws[..., 3:5], restart, cand) if err["multipath"] else None
        amb, lli = self._ambiguities(t, tracked)

        out = {"t": (t, "s")}
        out["sat_pos_ecef"] = (ref["sat_pos"], "m")  # at emission (for the IMU centre), ECEF frame at reception
        out["sat_clock"] = (ref["sat_clock"], "s")
        out["truth/antenna_pos_ecef"] = (ant_pos, "m")
        out["truth/antenna_vel_ecef"] = (ant_vel, "m/s")
        out["truth/range"] = (full(geo["range"]), "m")
        out["truth/range_rate"] = (full(rr), "m/s")
        out["truth/elevation"] = (full(geo["el"]), "rad")
        out["truth/azimuth"] = (full(geo["az"]), "rad")
        out["truth/receiver_clock"] = (rx_clk, "m")
        out["truth/receiver_clock_drift"] = (rx_clk_rate, "m/s")
        out["truth/satellite_clock"] = (full(sat_clk), "m")
        out["truth/satellite_clock_drift"] = (full(sat_clk_rate), "m/s")
        out["truth/troposphere"] = (full(trop), "m")
        out["truth/troposphere_rate"] = (full(trop_rate), "m/s")

        rolloff = np.array([x.rolloff_db for x in cfg.antennas])[None, :, None]
        on = err["noise"]
        for j, g in enumerate(self.signals):
            cj = np.flatnonzero(self.carries[cand, j])                      # candidate columns with signal j
            sel = (Ellipsis, cj)
            cn0 = noise.cn0_dbhz(off[sel], cfg.cn0_zenith_dbhz, rolloff, g.cn0_offset_db)
            sig_c, sig_p, sig_d = self._sigmas(cn0, g)
            scale = ((atmosphere.F_L1 if g.system == "G" else atmosphere.F_B1I) / g.freq_hz) ** 2
            iono, iono_rate = iono_ref[sel] * scale, iono_ref_rate[sel] * scale
            gd = C_LIGHT * self.group_delay_s[cand[cj], j] * err["group_delay"]
            if mpx is not None:
                mp_c = elevation_scale(el_safe[sel], cfg.multipath.code_sigma_m,
                                       cfg.multipath.elevation_scale_rad) * mpx[:, :, cj, j, 0]
                mp_p = elevation_scale(el_safe[sel], cfg.multipath.carrier_sigma_m,
                                       cfg.multipath.elevation_scale_rad) * mpx[:, :, cj, j, 1]
            else:
                mp_c = mp_p = np.zeros(cn0.shape)
            n_c = draws[:, :, cj, j, 0] * sig_c * on
            n_p = draws[:, :, cj, j, 1] * sig_p * on
            n_d = draws[:, :, cj, j, 2] * sig_d * on
            base = geo["range"][sel] + clk[sel] + trop[sel]
            code = base + gd + iono + mp_c + n_c
            carrier = (base - iono + mp_p + n_p) / g.wavelength_m + amb[..., cand[cj], j]
            doppler = -(rr[sel] + clk_rate[sel] - iono_rate + trop_rate[sel]) / g.wavelength_m + n_d
            keep = tracked[..., cand[cj], j]
            cols = cand[cj]

            def put(x, fill=np.nan, mask=True):
                res = np.full((m, a_count, s_count), fill)
                res[..., cols] = np.where(keep, x, fill) if mask else x
                return res

            p, q = f"obs/{g.name}", f"truth/{g.name}"
            out[f"{p}/code"] = (put(code), "m")
            out[f"{p}/carrier"] = (put(carrier), "cycles")
            out[f"{p}/doppler"] = (put(doppler), "Hz")
            out[f"{p}/cn0"] = (put(cn0), "dB-Hz")
            out[f"{p}/ambiguity"] = (amb[..., j], "cycles")
            out[f"{p}/lli"] = (lli[..., j], "")
            out[f"{q}/ionosphere"] = (put(iono, mask=False), "m")
            out[f"{q}/ionosphere_rate"] = (put(iono_rate, mask=False), "m/s")
            out[f"{q}/multipath_code"] = (put(mp_c, mask=False), "m")
            out[f"{q}/multipath_carrier"] = (put(mp_p, mask=False), "m")
            out[f"{q}/noise_code"] = (put(n_c, mask=False), "m")
            out[f"{q}/noise_carrier"] = (put(n_p, mask=False), "m")
            out[f"{q}/noise_doppler"] = (put(n_d, mask=False), "Hz")
            out[f"{q}/sigma_code"] = (put(sig_c * on, mask=False), "m")
            out[f"{q}/sigma_carrier"] = (put(sig_p * on, mask=False), "m")
            out[f"{q}/sigma_doppler"] = (put(sig_d * on, mask=False), "Hz")
        return out

    # ------------------------------------------------------------------ pieces
    def _antennas(self, pos, vel, quat_nb, omega_ib_b):
        """Antenna positions/velocities (M, A, 3) ECEF and C_b^e (M, 3, 3)."""
        lla = frames.ecef_to_lla(pos)
        c_en = frames.ecef_to_enu_matrix(lla[:, 0], lla[:, 1])              # C_e^n (M, 3, 3)
        c_nb = Rotation.from_quat(np.asarray(quat_nb, dtype=float).reshape(-1, 4)).as_matrix()
        c_be = np.einsum("mji,mjk->mik", c_en, c_nb)                        # C_b^e = (C_e^n)^T C_b^n
        w_eb = np.asarray(omega_ib_b, dtype=float).reshape(-1, 3) - np.einsum("mji,j->mi", c_be, _OMEGA)
        ant_pos = pos[:, None, :] + np.einsum("mij,aj->mai", c_be, self.lever)
        ant_vel = vel[:, None, :] + np.einsum("mij,maj->mai", c_be, np.cross(w_eb[:, None, :], self.lever[None]))
        return ant_pos, ant_vel, c_be

    def _antenna_geometry(self, ref, ant_pos, ant_vel):
        """Per-antenna range, range rate, line of sight, elevation/azimuth and their rates from the IMU-centre
        light-time solution (see the module docstring)."""
        x0 = ref["sat_pos"][:, None]                                        # (M, 1, S, 3) frame: ECEF at reception
        v_rot = ref["sat_vel"][:, None]
        v_in = v_rot + np.cross(_OMEGA, x0)                                 # inertial velocity in that frame
        tau0 = ref["tau"][:, None]
        r = ant_pos[:, :, None, :]
        d = np.zeros(tau0.shape[:1] + (ant_pos.shape[1],) + tau0.shape[2:])
        for _ in range(2):
            xs = x0 - v_in * d[..., None]
            d = np.linalg.norm(xs - r, axis=-1) / C_LIGHT - tau0
        xs = x0 - v_in * d[..., None]
        diff = xs - r
        rng_ = np.linalg.norm(diff, axis=-1)
        u = diff / rng_[..., None]
        v_r = ant_vel[:, :, None, :] + np.cross(_OMEGA, r)
        rr = np.einsum("masi,masi->mas", u, v_in - v_r) / (1.0 + np.einsum("masi,masi->mas", u, v_in) / C_LIGHT)
        m, a = ant_pos.shape[:2]
        el = np.empty(rng_.shape)
        az = np.empty(rng_.shape)
        for k in range(a):
            el[:, k], az[:, k] = elevation_azimuth(ant_pos[:, k], u[:, k])
        # line-of-sight rate in ECEF (rotating-frame relative velocity), then elevation/azimuth rates in ENU
        w = v_rot - ant_vel[:, :, None, :]
        u_dot = (w - u * np.einsum("masi,masi->mas", u, w)[..., None]) / rng_[..., None]
        lla = frames.ecef_to_lla(ant_pos.reshape(-1, 3)).reshape(ant_pos.shape)
        c_en = frames.ecef_to_enu_matrix(lla[..., 0], lla[..., 1])          # (M, A, 3, 3)
        enu = np.einsum("maij,masj->masi", c_en, u)
        enu_dot = np.einsum("maij,masj->masi", c_en, u_dot)
        el_rate = enu_dot[..., 2] / np.sqrt(np.maximum(1.0 - enu[..., 2] ** 2, 1e-12))
        hz = enu[..., 0] ** 2 + enu[..., 1] ** 2
        az_rate = (enu[..., 1] * enu_dot[..., 0] - enu[..., 0] * enu_dot[..., 1]) / np.maximum(hz, 1e-12)
        clock = ref["sat_clock"][:, None] - ref["sat_drift"][:, None] * d
        return {"range": rng_, "range_rate": rr, "los": u, "el": el, "az": az, "el_rate": el_rate,
                "az_rate": az_rate, "sat_clock": clock, "sat_drift": np.broadcast_to(ref["sat_drift"][:, None],
                                                                                     clock.shape)}

    def _clock(self, m):
        """Receiver clock bias (M, A) s and drift (M, A) s/s."""
        parts = [c.advance(m) for c in self.clocks]
        bias = np.stack([p[0] for p in parts], axis=1)
        drift = np.stack([p[1] for p in parts], axis=1)
        if bias.shape[1] == 1:
            bias = np.repeat(bias, self.n_ant, axis=1)
            drift = np.repeat(drift, self.n_ant, axis=1)
        return bias, drift

    def _draws(self, vis_c, cand):
        """Standard normals (M, A, C, G, 5) [code, carrier, Doppler, multipath code, multipath carrier] for
        the candidate columns; zero where the satellite is not visible. Each (antenna, satellite) stream draws
        5 numbers per signal of its system at each epoch where it is visible, in epoch order, so the draws do not
        depend on how the epochs are split into blocks."""
        m, a_count, c_count = vis_c.shape
        out = np.zeros((m, a_count, c_count, len(self.signals), 5))
        for a in range(a_count):
            for c, s in enumerate(cand):
                rows = np.flatnonzero(vis_c[:, a, c])
                if rows.size:
                    sigs = self.sys_signals[s]
                    out[rows[:, None], a, c, sigs[None, :]] = self.noise_rng[a][s].standard_normal(
                        (rows.size, sigs.size, 5))
        return out

    def _sigmas(self, cn0, g):
        nz = self.cfg.noise
        if nz.model == "constant":
            one = np.ones_like(cn0)
            return one * nz.code_sigma_m, one * nz.carrier_sigma_m, one * nz.doppler_sigma_hz
        return (noise.dll_sigma_m(cn0, g.chip_length_m, nz.dll_bandwidth_hz, nz.correlator_spacing_chips,
                                  nz.integration_time_s),
                noise.pll_sigma_m(cn0, g.wavelength_m, nz.pll_bandwidth_hz, nz.integration_time_s),
                noise.fll_sigma_hz(cn0, nz.fll_bandwidth_hz, nz.integration_time_s))

    def _ambiguities(self, t, tracked):
        """True integer ambiguities (M, A, S, G) and LLI flags (M, A, S, G) uint8 over this block.

        Events per channel, in time order: acquisition (a new random integer), random slips (Poisson, rate
        ``slip_rate_per_h``) and scheduled slips (the given or a random non-zero number of cycles). Each
        (antenna, satellite) draws its events from its own stream, in time order, so blocks do not matter.
        """
        m = t.size
        cfg = self.cfg
        prev = np.concatenate([self.tracked[None], tracked[:-1]], axis=0)
        acq = tracked & ~prev                                               # (M, A, S, G)
        events: dict[tuple, list] = {}
        for k, a, s, g in zip(*np.nonzero(acq)):
            events.setdefault((a, s), []).append((k, g, 0, None))
        if cfg.errors["cycle_slips"]:
            t_end = t[-1]
            for a, s, g in zip(*np.nonzero(self.next_slip <= t_end)):
                events.setdefault((a, s), []).append((None, g, 1, None))  # Poisson chain starts in this block
            for sl in cfg.slips:
                k = int(np.searchsorted(t, sl.t_s - 1e-9))  # first epoch at or after the slip
                if k >= m or sl.t_s <= self.t_last:
                    continue
                ants = [sl.antenna] if sl.antenna is not None else range(self.n_ant)
                sats = [self.sat_index[sl.sat]] if sl.sat is not None else range(len(self.sat_ids))
                sigs = [self.sig_index[sl.signal]] if sl.signal is not None else range(len(self.signals))
                for a in ants:
                    for s in sats:
                        for g in sigs:
                            events.setdefault((a, s), []).append((k, g, 2, sl.cycles))
        amb = np.broadcast_to(self.amb, (m,) + self.amb.shape).copy()
        lli = np.zeros((m,) + self.amb.shape, dtype=np.uint8)
        big = cfg.ambiguity_max_cycles
        for (a, s), evs in events.items():
            gen = self.event_rng[a][s]
            heap = []
            for k, g, kind, cyc in evs:
                if kind == 1:
                    k = int(np.searchsorted(t, self.next_slip[a, s, g] - 1e-9))
                heapq.heappush(heap, (k, g, kind, 0 if cyc is None else cyc, cyc is None))
            while heap:
                k, g, kind, cyc, random_cycles = heapq.heappop(heap)
                if kind == 0:
                    amb[k:, a, s, g] = gen.integers(-big, big + 1)
                    lli[k, a, s, g] |= LLI_LOSS_OF_LOCK
                    continue
                if kind == 1:  # Poisson slip: schedule the next one of this chain first
                    self.next_slip[a, s, g] += gen.exponential(1.0 / self.slip_rate)
                    if self.next_slip[a, s, g] <= t[-1]:
                        heapq.heappush(heap, (int(np.searchsorted(t, self.next_slip[a, s, g] - 1e-9)), g, 1, 0,
                                              True))
                if random_cycles:
                    cyc = int(gen.integers(1, 51)) * (1 if gen.random() < 0.5 else -1)
                if tracked[k, a, s, g]:
                    amb[k:, a, s, g] += cyc
                    lli[k, a, s, g] |= LLI_LOSS_OF_LOCK
        self.amb = amb[-1].copy()
        self.tracked = tracked[-1].copy()
        self.t_last = float(t[-1])
        return amb, lli

