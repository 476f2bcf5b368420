"""pyins' loosely coupled INS/GNSS filter (PyPI ``python-ins``) refereed by simkit on ``airborne_stim300``.

A filter nobody here wrote, in its own conventions: NED navigation frame, body forward-right-down, Euler
roll/pitch/heading in degrees, latitude/longitude in degrees, IMU readings as a pandas DataFrame. This wrapper
implements simkit's plugin interface (:mod:`simkit.referee.plugin`):

- ``predict`` stores each IMU sample rotated from body right-forward-up to forward-right-down;
- ``update`` computes a GPS L1 C/A single-point position of the first antenna from the code pseudoranges
  (iterative least squares with the satellite clock, the Sagnac rotation and a 2.3 m / sin(elevation)
  troposphere; ionosphere and group delays left in: metre-level fixes);
- ``solution`` runs pyins' extended (feedback) Kalman filter ``pyins.filters.run_feedback_filter`` over the
  stored IMU data with the fixes as ``pyins.measurements.Position`` (with pyins' own lever-arm handling), and
  converts its NED output and standard deviations to simkit's conventions with
  :func:`simkit.referee.solution_from_ned`; pyins' standardised position innovations give the NIS (3 dof).

Run: ``python examples/pyins_loosely_coupled.py airborne_stim300.h5 [--duration 300] [--report DIR] [--csv OUT]``
(simulate the file first with ``simkit run airborne_stim300``); ``--csv`` writes pyins' native NED output, which
``simkit score airborne_stim300.h5 OUT.csv --spec examples/spec_airborne.toml`` scores from the command line.
"""
from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from pyins import filters, inertial_sensor, measurements, strapdown
from scipy.spatial.transform import Rotation

from simkit import frames, referee

C = 299792458.0
OMEGA_E = 7.2921151467e-5     # GPS value (IS-GPS-200)
DEG_H = np.pi / 180 / 3600    # 1 deg/h in rad/s


def spp(sat_pos, sat_clock, code, x0, iterations=8):
    """Code single-point position (3,) m ECEF and receiver clock (m) from (S, 3) satellite positions at emission
    (emission-epoch ECEF), (S,) clocks (s) and (S,) pseudoranges (m); None with fewer than 5 satellites."""
    use = np.isfinite(code) & np.all(np.isfinite(sat_pos), axis=1) & np.isfinite(sat_clock)
    if use.sum() < 5:
        return None
    s, dts, rho = sat_pos[use], sat_clock[use], code[use]
    x = np.append(np.asarray(x0, dtype=float), 0.0)
    for _ in range(iterations):
        los = s - x[:3]
        theta = OMEGA_E * np.linalg.norm(los, axis=1) / C          # Earth rotation during the signal's flight
        c, sn = np.cos(theta), np.sin(theta)
        rot = np.stack([c * s[:, 0] + sn * s[:, 1], -sn * s[:, 0] + c * s[:, 1], s[:, 2]], axis=1)
        los = rot - x[:3]
        r = np.linalg.norm(los, axis=1)
        up = x[:3] / np.linalg.norm(x[:3])
        sin_el = np.clip(los @ up / r, 0.05, 1.0)
        res = rho - (r + x[3] - C * dts + 2.3 / sin_el)
        h = np.hstack([-los / r[:, None], np.ones((len(r), 1))])
        dx = np.linalg.lstsq(h * sin_el[:, None], res * sin_el, rcond=None)[0]
        x += dx
        if np.linalg.norm(dx[:3]) < 1e-4:
            break
    return x


class PyinsLooselyCoupled:
    """simkit plugin wrapping pyins' feedback Kalman filter with GNSS position fixes (module docstring).
    ``position_sd_m``: fix accuracy given to pyins; ``signal``: the code used for the fixes; ``gyro``/``accel``
    models: pyins ``EstimationModel`` keyword arguments in rad/s, rad/s/sqrt(s), m/s^2, m/s/sqrt(s)."""

    def __init__(self, position_sd_m=5.0, signal="L1C", gyro=None, accel=None, time_step_s=1.0):
        self.position_sd_m, self.signal, self.time_step_s = position_sd_m, signal, time_step_s
        self.gyro = gyro or {"bias_sd": np.full(3, 10 * DEG_H), "noise": np.full(3, 0.2 * np.pi / 180 / 60)}
        self.accel = accel or {"bias_sd": np.full(3, 1e-3 * 9.8), "noise": np.full(3, 0.1 / 60)}
        self.imu, self.fixes, self.init, self.x, self.native = [], [], None, None, None

    def start(self, init):
        self.init = init
        self.x = init.pos_ecef

    def predict(self, imu):
        self.imu.append((imu.t, *imu.gyro, *imu.accel))

    def update(self, gnss):
        code = gnss.code.get(self.signal)
        if code is None:
            return
        x = spp(gnss.sat_pos_ecef, gnss.sat_clock, code[0], self.x)
        if x is not None:
            self.x = x[:3]
            lla = frames.ecef_to_lla(x[:3])
            self.fixes.append((gnss.t, np.degrees(lla[0]), np.degrees(lla[1]), lla[2]))

    def initial_pva(self, t0):
        """pyins' initial position-velocity-attitude (degrees, NED, FRD) at time ``t0`` from ``start``'s truth."""
        i = self.init
        lla = frames.ecef_to_lla(i.pos_ecef)
        ned = frames.enu_to_ned(i.vel_enu)
        rph = Rotation.from_matrix(frames.attitude_to_ned_frd(Rotation.from_quat(i.quat_nb)).as_matrix())
        roll_pitch_heading = rph.as_euler("ZYX", degrees=True)[::-1]
        values = [np.degrees(lla[0]), np.degrees(lla[1]), lla[2], *ned, *roll_pitch_heading]
        return pd.Series(values, index=["lat", "lon", "alt", "VN", "VE", "VD", "roll", "pitch", "heading"],
                         name=t0)

    def solution(self):
        data = np.array(self.imu)
        frd = np.hstack([frames.enu_to_ned(data[:, 1:4]), frames.enu_to_ned(data[:, 4:7])])  # RFU -> FRD swap
        imu = pd.DataFrame(frd, index=data[:, 0], columns=["gyro_x", "gyro_y", "gyro_z",
                                                          "accel_x", "accel_y", "accel_z"])
        increments = strapdown.compute_increments_from_imu(imu, "rate")
        fixes = pd.DataFrame([f[1:] for f in self.fixes], index=[f[0] for f in self.fixes],
                             columns=["lat", "lon", "alt"])
        lever_frd = frames.enu_to_ned(self.init.lever_arm_b[0])
        # pyins' batch filter shows no progress: say what the next minute or two is (660-960 samples/s here)
        print(f"pyins: run_feedback_filter over {len(data)} IMU samples and {len(fixes)} fixes ...", file=sys.stderr,
              flush=True)
        result = filters.run_feedback_filter(
            self.initial_pva(data[0, 0]), position_sd=1.0, velocity_sd=0.1, level_sd=0.05, azimuth_sd=0.2,
            increments=increments, gyro_model=inertial_sensor.EstimationModel(**self.gyro),
            accel_model=inertial_sensor.EstimationModel(**self.accel),
            measurements=[measurements.Position(fixes, self.position_sd_m, lever_frd)],
            time_step=self.time_step_s)
        sd = result.trajectory_sd
        traj = result.trajectory.loc[sd.index]
        # pyins returns standardised innovations (identity covariance): their squared norm is the NIS
        nu = result.innovations["Position"]
        nis = pd.Series((nu.values ** 2).sum(axis=1), index=nu.index).reindex(sd.index)
        self.native = (traj, sd, nis)
        sol = referee.solution_from_ned(
            traj.index.values, np.radians(traj.lat.values), np.radians(traj.lon.values), traj.alt.values,
            vel_ned=traj[["VN", "VE", "VD"]].values, roll=np.radians(traj.roll.values),
            pitch=np.radians(traj.pitch.values), heading=np.radians(traj.heading.values),
            sd_ned=sd[["north", "east", "down"]].values, sd_vel_ned=sd[["VN", "VE", "VD"]].values,
            sd_rph=np.radians(sd[["roll", "pitch", "heading"]].values),
            config={"filter": "pyins.filters.run_feedback_filter", "position_sd_m": self.position_sd_m,
                    "signal": self.signal, "fixes": len(self.fixes)})
        dof = np.where(np.isfinite(nis.values), 3.0, 0.0)
        return dataclasses.replace(sol, extras={"nis": nis.values, "nis_dof": dof},
                                   extra_units={"nis": "1", "nis_dof": "1"})


def write_native_csv(path, traj, sd, nis) -> None:
    """pyins' own output (NED, degrees, roll/pitch/heading, standard deviations) and the NIS of its position
    innovations as a simkit score CSV (docs/referee.md columns)."""
    table = pd.DataFrame({
        "t_s": traj.index.values, "lat_deg": traj.lat.values, "lon_deg": traj.lon.values, "h_m": traj.alt.values,
        "vel_n_m_per_s": traj.VN.values, "vel_e_m_per_s": traj.VE.values, "vel_d_m_per_s": traj.VD.values,
        "roll_deg": traj.roll.values, "pitch_deg": traj.pitch.values, "heading_deg": traj.heading.values,
        "sd_n_m": sd.north.values, "sd_e_m": sd.east.values, "sd_d_m": sd.down.values,
        "sd_vel_n_m_per_s": sd.VN.values, "sd_vel_e_m_per_s": sd.VE.values, "sd_vel_d_m_per_s": sd.VD.values,
        "sd_roll_deg": sd.roll.values, "sd_pitch_deg": sd.pitch.values, "sd_heading_deg": sd.heading.values,
        "nis": nis.values, "nis_dof": np.where(np.isfinite(nis.values), 3, 0)})
    with open(path, "w") as f:
        f.write("# pyins.filters.run_feedback_filter output, NED / forward-right-down, degrees\n")
        table.to_csv(f, index=False, float_format="%.10f")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description="Referee pyins' loosely coupled filter on a simkit file.")
    p.add_argument("file")
    p.add_argument("--duration", type=float, help="seconds of the file to use (default: all)")
    p.add_argument("--json", help="write the score and timing as JSON")
    p.add_argument("--report", help="directory for the Markdown report and error plots")
    p.add_argument("--csv", help="also write pyins' native NED output as a CSV for `simkit score`")
    args = p.parse_args(argv)
    flt = PyinsLooselyCoupled()
    res = referee.run_filter(flt, args.file, duration_s=args.duration, progress=True)
    if args.csv:
        write_native_csv(args.csv, *flt.native)
    referee.write_run_outputs(res, "pyins run_feedback_filter (loosely coupled)", args.file, args.json)
    if args.report:
        from simkit.plots import score_figures

        Path(args.report).mkdir(exist_ok=True)
        score_figures(res.score, args.report, "pyins run_feedback_filter (loosely coupled)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
