"""simkit's own 15-state loosely coupled Kalman filter behind the referee's plugin interface.

The same interface a third-party filter implements (:mod:`simkit.referee.plugin`, and the pyins example beside
this file), so both are refereed by the same code on the same file:

- ``start`` takes the true initial state (a referee run compares filters, not alignment procedures);
- ``predict`` stores each IMU sample (body right-forward-up, rad/s and m/s^2, simkit's own conventions);
- ``update`` stores the GNSS epoch's code and Doppler of one antenna and signal;
- ``solution`` forms code/Doppler single-point fixes for all stored epochs at once
  (:func:`simkit.estimators.spp`) and runs :class:`simkit.estimators.KalmanFilter15` over the IMU samples with
  those fixes and the antenna lever arm; its covariance carries the filter's own error-state names, which the
  referee's NEES understands (phi, dv, d_lat/d_lon/d_h).

Run: ``python examples/simkit_kf15.py airborne_stim300.h5 [--duration 300] [--report DIR]`` (simulate the file
first with ``simkit run airborne_stim300``), then the pyins example on the same file for the side-by-side.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from simkit import estimators, frames, referee

DEG_H = np.pi / 180 / 3600    # 1 deg/h in rad/s


class SimkitKf15:
    """simkit plugin around :class:`simkit.estimators.KalmanFilter15` (module docstring). ``signal`` and
    ``antenna`` choose the fixes; ``config`` is a :class:`simkit.estimators.FilterConfig` (noise densities in
    rad/s/sqrt(Hz) and m/s^2/sqrt(Hz), initial sigmas)."""

    def __init__(self, signal="L1C", antenna=0, config=None, sigma_code_m=3.0, sigma_doppler_m_per_s=0.1):
        self.signal, self.antenna = signal, antenna
        self.config = config or estimators.FilterConfig(gyro_arw=0.15 * np.pi / 180 / 60, accel_vrw=0.06 / 60,
                                                        p0_gyro_bias=0.5 * DEG_H, p0_accel_bias=0.05e-2 * 9.8)
        self.sigma_code_m, self.sigma_doppler_m_per_s = sigma_code_m, sigma_doppler_m_per_s
        self.imu, self.epochs, self.init = [], [], None

    def start(self, init):
        self.init = init

    def predict(self, imu):
        self.imu.append((imu.t, *imu.gyro, *imu.accel))

    def update(self, gnss):
        if self.signal in gnss.code:
            self.epochs.append(gnss)

    def _fixes(self):
        e = self.epochs
        sat_ids = e[0].sat_id
        fixes = estimators.spp(
            np.array([g.t for g in e]), np.stack([g.code[self.signal][self.antenna] for g in e]),
            np.stack([g.doppler[self.signal][self.antenna] for g in e]),
            np.full(len(sat_ids), e[0].wavelength_m[self.signal]), np.stack([g.sat_pos_ecef for g in e]),
            np.stack([g.sat_clock for g in e]), np.array([s[0] for s in sat_ids]),
            sigma_code_m=self.sigma_code_m, sigma_doppler_m_per_s=self.sigma_doppler_m_per_s)
        return estimators.GnssFixes(fixes.t, fixes.pos_ecef, fixes.vel_enu, fixes.pos_cov_enu, fixes.vel_cov_enu,
                                    self.init.lever_arm_b[self.antenna])

    def solution(self):
        data = np.array(self.imu)
        imu = estimators.ImuData(data[:, 0], data[:, 1:4], data[:, 4:7])
        i = self.init
        init = estimators.InitialState(i.t, frames.ecef_to_lla(i.pos_ecef), np.asarray(i.vel_enu),
                                       np.asarray(i.quat_nb))
        return estimators.KalmanFilter15(self.config, init).run(imu, self._fixes())


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description="Referee simkit's KF15 through the plugin interface on a simkit file.")
    p.add_argument("file")
    p.add_argument("--duration", type=float, help="seconds of the file to use (default: all)")
    p.add_argument("--json", help="write the score and timing as JSON")
    p.add_argument("--report", help="directory for the Markdown report and error plots")
    args = p.parse_args(argv)
    res = referee.run_filter(SimkitKf15(), args.file, duration_s=args.duration, progress=True)
    referee.write_run_outputs(res, "simkit KalmanFilter15 (loosely coupled)", args.file, args.json)
    if args.report:
        from simkit.plots import score_figures

        Path(args.report).mkdir(exist_ok=True)
        score_figures(res.score, args.report, "simkit KalmanFilter15 (loosely coupled)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
