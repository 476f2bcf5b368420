"""A drive recorded as a 1 Hz NMEA log with 2 m noise (made from simkit's analytic drive, so the true path is
known), replayed at 100 Hz through ``[trajectory] source``: the replayed path is within the noise of the true
path, the truth is inertially consistent (RK4 strapdown of its rates reproduces it), and the specific force and
body rates have no steps at the log's samples. The other attitude rules and formats are replayed too."""
import numpy as np
import pymap3d
import pytest

from log_writers import drive_truth, nmea_lines, noisy_log
from simkit.scenario import load
from simkit.trajectory import Trajectory
from test_trajectory_consistency import _strapdown_errors

SIGMA = 2.0
OFFSET_S = 10.0        # the replay starts 10 s into the log and stops 10 s before its end


@pytest.fixture(scope="module")
def truth_10hz():
    return drive_truth(10.0)


@pytest.fixture(scope="module")
def nmea_log(tmp_path_factory, truth_10hz):
    t, lat, lon, h, _ = noisy_log(truth_10hz, 10, SIGMA, seed=3)
    path = tmp_path_factory.mktemp("logs") / "drive.nmea"
    path.write_text("\n".join(nmea_lines(t, lat, lon, h)) + "\n")
    return path


def replay(source, rate=100.0, duration=280.0, start="2026-04-27T06:00:10Z", **keys):
    sc = load({"scenario": {"name": "replay", "start": start, "duration_s": duration},
               "trajectory": {"rate_hz": rate, "source": str(source), **keys}})
    blocks = list(Trajectory(sc.trajectory, sc.duration_s).blocks(block_samples=7000))
    return sc, {k: np.concatenate([getattr(b, k) for b in blocks]) for k in blocks[0].arrays()}


def enu_errors(replayed, true_lla):
    e, n, u = pymap3d.ecef2enu(*replayed.T, np.degrees(true_lla[:, 0]), np.degrees(true_lla[:, 1]), true_lla[:, 2])
    return np.stack([e, n, u], -1)


def test_nmea_drive_replayed_at_100hz_within_the_noise_consistent_and_smooth(nmea_log):
    sc, rp = replay(nmea_log, position_sigma_m=SIGMA)
    true100 = drive_truth(100.0)
    k0 = int(OFFSET_S * 100)
    err = enu_errors(rp["pos_ecef"], true100["pos_lla"][k0:k0 + len(rp["t"])])
    rms = np.sqrt(np.mean(err**2, axis=0))
    print(f"\nreplay of a 1 Hz NMEA log with {SIGMA} m noise at 100 Hz: RMS error E/N/U {rms.round(3)} m, "
          f"max {np.abs(err).max():.2f} m")
    assert np.all(rms < SIGMA)
    assert np.all(rms < 0.75 * SIGMA)      # measured 1.13, 1.15, 0.64 m: the fit removes about half the noise

    pos_err, vel_err, att_err = _strapdown_errors(rp, 100.0)
    print(f"closure over {sc.duration_s:g} s: position {pos_err:.2e} m, velocity {vel_err:.2e} m/s, "
          f"attitude {att_err:.2e} arcsec")
    assert pos_err < 1e-4 and vel_err < 1e-6 and att_err < 1e-3

    # a step s at a log sample would show as s in the jump of the first difference across it
    at_log = np.arange(100, len(rp["t"]) - 101, 100)
    for key in ("f_ib_b", "omega_ib_b"):
        d1 = np.diff(rp[key], axis=0)
        kink = np.abs(d1[at_log] - 0.5 * (d1[at_log - 1] + d1[at_log + 1])).max()
        scale = np.abs(rp[key] - rp[key].mean(0)).max()
        print(f"{key}: largest change of slope across a log sample {kink:.2e} (signal range {scale:.2e})")
        assert kink < 1e-6 * scale


def test_velocity_following_attitude_and_rates_against_the_true_drive(nmea_log):
    """The ground rule puts body y along the fitted velocity: heading within a degree or two of the true drive's
    (the heading error of 2 m noise over 1 s at 10-15 m/s), roll 0 (to roundoff)."""
    _, rp = replay(nmea_log, position_sigma_m=SIGMA)
    true100 = drive_truth(100.0)
    k0 = int(OFFSET_S * 100)
    dh = np.degrees(np.angle(np.exp(1j * (rp["euler"][:, 2] - true100["euler"][k0:k0 + len(rp["t"]), 2]))))
    print(f"\nheading error RMS {np.sqrt(np.mean(dh**2)):.2f} deg, max {np.abs(dh).max():.2f} deg")
    assert np.sqrt(np.mean(dh**2)) < 2.0
    assert np.abs(rp["euler"][:, 1]).max() < 1e-12


def test_noise_estimated_from_the_log_when_not_stated(nmea_log):
    sc, _ = replay(nmea_log, duration=60.0)
    path = sc.trajectory.path
    print(f"\nestimated sigma E/N/U {path.sigma_m.round(3)} m (true {SIGMA} m)")
    assert path.sigma_source == "estimated"
    assert np.all(np.abs(path.sigma_m - SIGMA) < 0.3 * SIGMA)


def test_coordinated_rule_closure_on_a_turning_flight(tmp_path):
    """An airborne track (airborne_stim300 from 60 s to 400 s: climb, turns at 3 deg/s and 150 m/s; 10 Hz,
    0.5 m noise) replayed with the coordinated-turn rule: the bank and its rate come from the fitted jerk, and the
    strapdown closure still holds."""
    sc = load("airborne_stim300", ["trajectory.rate_hz=10.0", "scenario.duration_s=400.0"])
    blocks = list(Trajectory(sc.trajectory, sc.duration_s).blocks())
    tr = {k: np.concatenate([getattr(b, k) for b in blocks]) for k in blocks[0].arrays()}
    t, lat, lon, h, _ = noisy_log(tr, 1, 0.5, seed=5, start_index=500)
    rows = ["gps_week,gps_sow,lat_deg,lon_deg,h_m"] + [
        f"{sc.start_week},{sc.start_sow + tt:.17g},{la:.17g},{lo:.17g},{hh:.17g}" for tt, la, lo, hh in zip(t, lat, lon, h)]
    path = tmp_path / "flight.csv"
    path.write_text("\n".join(rows) + "\n")
    start = sc.start.strftime("%Y-%m-%dT%H:") + "01:00Z"      # 60 s after the scenario start
    _, rp = replay(path, rate=200.0, duration=330.0, start=start, attitude="coordinated", position_sigma_m=0.5)
    bank = np.degrees(np.abs(rp["euler"][:, 1])).max()
    pos_err, vel_err, att_err = _strapdown_errors(rp, 200.0)
    print(f"\ncoordinated replay: max bank {bank:.1f} deg; closure {pos_err:.2e} m, {att_err:.2e} arcsec")
    assert bank > 20.0
    assert pos_err < 1e-3 and att_err < 1e-2


def test_logged_attitude_is_followed_and_closure_holds(tmp_path, truth_10hz):
    """A CSV with roll/pitch/heading columns (the true drive's, plus 0.1 deg noise and a 3 deg roll wave):
    attitude rule 'log' follows them within the noise."""
    rng = np.random.default_rng(9)
    tr = truth_10hz
    euler = tr["euler"].copy()
    euler[:, 1] += np.radians(3.0) * np.sin(2 * np.pi * tr["t"] / 15.0)
    noisy = euler + np.radians(0.1) * rng.standard_normal(euler.shape)
    lla = tr["pos_lla"]
    rows = ["utc,lat_rad,lon_rad,h_m,roll_deg,pitch_deg,heading_deg"]
    for k in range(len(tr["t"])):
        s = 6 * 3600 + tr["t"][k]
        stamp = f"2026-04-27T{int(s // 3600):02d}:{int(s % 3600 // 60):02d}:{s % 60:09.6f}Z"
        rows.append(f"{stamp},{lla[k, 0]:.17g},{lla[k, 1]:.17g},{lla[k, 2]:.17g},{np.degrees(noisy[k, 1]):.17g},"
                    f"{np.degrees(noisy[k, 0]):.17g},{np.degrees(noisy[k, 2]) % 360:.17g}")
    path = tmp_path / "att.csv"
    path.write_text("\n".join(rows) + "\n")
    sc, rp = replay(path, duration=100.0, position_sigma_m=0.01, attitude_sigma_deg=0.1)
    assert sc.trajectory.path.rule == "log"
    k0 = int(OFFSET_S * 10)
    ref = euler[k0:k0 + 1001]
    d = rp["euler"][::10] - ref
    d[:, 2] = np.angle(np.exp(1j * d[:, 2]))
    rms = np.degrees(np.sqrt(np.mean(d**2, axis=0)))
    pos_err, vel_err, att_err = _strapdown_errors(rp, 100.0)
    print(f"\nlogged attitude: RMS error pitch/roll/heading {rms.round(4)} deg; closure {pos_err:.2e} m, "
          f"{att_err:.2e} arcsec")
    assert np.all(rms < 0.1)
    assert pos_err < 1e-4 and att_err < 1e-3


def _gpx(t, lat, lon, h):
    from datetime import datetime, timedelta, timezone

    start = datetime(2026, 4, 27, 6, 0, 0, tzinfo=timezone.utc)
    pts = "".join(f'<trkpt lat="{la:.10f}" lon="{lo:.10f}"><ele>{hh:.4f}</ele><time>'
                  f'{(start + timedelta(seconds=float(tt))).strftime("%Y-%m-%dT%H:%M:%S.%fZ")}</time></trkpt>\n'
                  for tt, la, lo, hh in zip(t, lat, lon, h))
    return ('<?xml version="1.0"?>\n<gpx version="1.1" creator="test" xmlns="http://www.topografix.com/GPX/1/1">'
            f"<trk><trkseg>\n{pts}</trkseg></trk></gpx>\n")


@pytest.mark.parametrize("every, sigma, gap, bound", [
    (50, 0.3, None, 1.5),               # 0.2 Hz: the 60 m-radius turn is sampled every 75 m (measured 0.72 m)
    (10, 1.0, (120.0, 128.0), 1.0)])    # 1 Hz with an 8 s gap in the weave (measured 0.81 m)
def test_sparse_and_gapped_gpx_logs(tmp_path, truth_10hz, every, sigma, gap, bound):
    """A 0.2 Hz log (5 s between samples) and a 1 Hz log with an 8 s gap (bridged: below max_gap_s = 10 s):
    both replay with the closure intact; the horizontal error RMS against the true drive stays bounded."""
    t, lat, lon, h, _ = noisy_log(truth_10hz, every, sigma, seed=11)
    if gap is not None:
        keep = (t <= gap[0]) | (t >= gap[1])
        t, lat, lon, h = t[keep], lat[keep], lon[keep], h[keep]
    path = tmp_path / "drive.gpx"
    path.write_text(_gpx(t, lat, lon, h))
    _, rp = replay(path, position_sigma_m=sigma)
    true100 = drive_truth(100.0)
    k0 = int(OFFSET_S * 100)
    err = np.linalg.norm(enu_errors(rp["pos_ecef"], true100["pos_lla"][k0:k0 + len(rp["t"])])[:, :2], axis=1)
    pos_err, vel_err, att_err = _strapdown_errors(rp, 100.0)
    print(f"\nlog every {every / 10:g} s, sigma {sigma} m, gap {gap}: horizontal error RMS "
          f"{np.sqrt(np.mean(err**2)):.2f} m, max {err.max():.2f} m; closure {pos_err:.1e} m")
    assert pos_err < 1e-4 and att_err < 1e-3
    assert np.sqrt(np.mean(err**2)) < bound


def test_logged_velocity_with_a_stated_accuracy_tightens_the_fit(tmp_path, truth_10hz):
    """RMC speed and course (the true horizontal velocity plus 0.1 m/s noise) enter the fit as slope rows when
    trajectory.velocity_sigma_m_per_s states their accuracy; without it they are ignored (documented)."""
    t, lat, lon, h, idx = noisy_log(truth_10hz, 10, SIGMA, seed=3)
    vel = truth_10hz["vel_enu"][idx] + np.random.default_rng(4).normal(0.0, 0.1, (len(idx), 3))
    path = tmp_path / "drive_rmc.nmea"
    path.write_text("\n".join(nmea_lines(t, lat, lon, h, vel_enu=vel)) + "\n")
    true100 = drive_truth(100.0)
    k0 = int(OFFSET_S * 100)
    rms = {}
    for key, extra in (("positions", {}), ("with velocity", {"velocity_sigma_m_per_s": 0.1})):
        _, rp = replay(path, position_sigma_m=SIGMA, **extra)
        err = enu_errors(rp["pos_ecef"], true100["pos_lla"][k0:k0 + len(rp["t"])])
        rms[key] = np.sqrt(np.mean(err[:, :2] ** 2))
        if extra:
            pos_err, _, att_err = _strapdown_errors(rp, 100.0)
            assert pos_err < 1e-4 and att_err < 1e-3
    print(f"\nhorizontal RMS error: positions only {rms['positions']:.3f} m, with RMC velocity "
          f"{rms['with velocity']:.3f} m")
    assert rms["with velocity"] < 0.8 * rms["positions"]


def test_the_bundled_example_replays_the_drive():
    """examples/replay_drive.toml (its log made as in the first test, with RMC): the same accuracy."""
    from pathlib import Path

    sc = load(Path(__file__).resolve().parents[1] / "examples" / "replay_drive.toml", ["imu.preset=ideal"])
    blocks = list(Trajectory(sc.trajectory, sc.duration_s).blocks())
    rp = {k: np.concatenate([getattr(b, k) for b in blocks]) for k in blocks[0].arrays()}
    true100 = drive_truth(100.0)
    k0 = int(OFFSET_S * 100)
    rms = np.sqrt(np.mean(enu_errors(rp["pos_ecef"], true100["pos_lla"][k0:k0 + len(rp["t"])]) ** 2, axis=0))
    assert np.all(rms < SIGMA)
