"""Segment kinds: the manoeuvre each one promises, with continuous (jerk-limited) specific force and body rate."""
import numpy as np
import pytest

from simkit import frames
from simkit.errors import ScenarioError
from simkit.scenario import load

from test_trajectory_consistency import _strapdown_errors


def _run(segments, initial=None, rate=200.0, duration=None, coordinated=True):
    data = {"scenario": {"name": "t", "start": "2026-01-01T00:00:00Z", "duration_s": duration or 100.0},
            "trajectory": {"rate_hz": rate, "origin": {"lat_deg": 45.0, "lon_deg": 7.0, "height_m": 1000.0},
                           "initial": initial or {"speed_m_per_s": 200.0}, "coordinated_turns": coordinated,
                           "segment": segments}}
    sc = load(data)
    if duration is None:
        data["scenario"]["duration_s"] = sc.trajectory.planned_s + 2.0
        sc = load(data)
    from simkit.trajectory import Trajectory

    blocks = list(Trajectory(sc.trajectory, sc.duration_s).blocks(block_samples=997))
    return sc, {k: np.concatenate([getattr(b, k) for b in blocks]) for k in blocks[0].arrays()}


def _assert_smooth(truth, rate):
    """No steps in specific force or body rate: second differences over 2h are ~4x those over h for a smooth
    signal (they scale with h^2), ~2x at a kink, and equal for a step (the same jump at any spacing)."""
    for key in ("f_ib_b", "omega_ib_b"):
        x = truth[key]
        d1 = np.abs(x[2:] - 2 * x[1:-1] + x[:-2]).max()
        d2 = np.abs(x[4:] - 2 * x[2:-2] + x[:-4]).max()
        assert d2 > 1.5 * d1, (key, d1, d2)


def test_coordinated_turn_by_load_factor_has_the_bank_and_no_side_force():
    sc, tr = _run([{"kind": "turn", "load_factor_g": 5.0, "angle_deg": 180.0}])
    g = np.linalg.norm(tr["f_ib_b"], axis=1) / 9.80665
    assert g.max() == pytest.approx(5.0, rel=0.01)
    bank = np.degrees(np.abs(tr["euler"][:, 1])).max()
    assert bank == pytest.approx(np.degrees(np.arccos(1 / 5.0)), abs=0.2)
    assert np.abs(tr["f_ib_b"][:, 0]).max() < 0.1  # coordinated: no lateral specific force
    heading = np.degrees(np.unwrap(tr["euler"][:, 2]))
    assert heading[-1] - heading[0] == pytest.approx(180.0, abs=1e-6)
    _assert_smooth(tr, 200.0)


def test_turn_by_radius_flies_the_circle():
    sc, tr = _run([{"kind": "turn", "radius_m": 2000.0, "angle_deg": 360.0, "ramp_s": 0.5}],
                  coordinated=False)
    enu = np.stack(frames.ecef_to_enu_vec(tr["pos_ecef"] - tr["pos_ecef"][0], *tr["pos_lla"][0, :2]), 0)
    assert np.hypot(enu[:, 0], enu[:, 1]).max() == pytest.approx(4000.0, rel=0.01)


def test_rolls_climbs_loops_and_speed_changes():
    sc, tr = _run([{"kind": "roll", "rate_deg_per_s": 200.0, "rolls": 2, "ramp_s": 0.2},
                   {"kind": "climb", "flight_path_deg": 20.0, "pitch_rate_deg_per_s": 5.0},
                   {"kind": "climb", "flight_path_deg": 0.0},
                   {"kind": "loop", "radius_m": 1500.0},
                   {"kind": "accelerate", "accel_m_per_s2": 5.0, "target_speed_m_per_s": 250.0},
                   {"kind": "pullup", "load_factor_g": 4.0, "flight_path_deg": 30.0}])
    assert np.degrees(np.abs(tr["omega_ib_b"][:, 1])).max() == pytest.approx(200.0, rel=0.01)
    speed = np.linalg.norm(tr["vel_enu"], axis=1)
    assert speed[-1] == pytest.approx(250.0, abs=1e-6)
    pitch = np.degrees(tr["euler"][:, 0])
    assert pitch[-1] == pytest.approx(30.0, abs=1e-6) and pitch.max() == pytest.approx(90.0, abs=0.1)
    _assert_smooth(tr, 200.0)
    pos, vel, att = _strapdown_errors(tr, 200.0)
    assert pos < 0.05 and att < 0.5


def test_waypoints_pass_through_the_points_within_earth_curvature():
    pts = [[2000.0, 1500.0, 50.0], [4000.0, 1000.0, 0.0], [6000.0, 3000.0, -100.0]]
    sc, tr = _run([{"kind": "waypoints", "points_enu_m": pts}],
                  initial={"speed_m_per_s": 100.0, "heading_deg": 60.0}, coordinated=True)
    lat0, lon0 = tr["pos_lla"][0, :2]
    enu = frames.ecef_to_enu_vec(tr["pos_ecef"] - tr["pos_ecef"][0], lat0, lon0)
    for p in pts:
        d = np.linalg.norm(enu - p, axis=1).min()
        curvature = np.linalg.norm(p) ** 2 / (2 * 6.37e6)
        assert d < 2 * curvature + 0.5, (p, d)  # curvature drop and meridian convergence, ~d^2/2R each
    _assert_smooth(tr, 200.0)


def test_weave_and_generic_rates():
    sc, tr = _run([{"kind": "weave", "heading_amplitude_deg": 10.0, "period_s": 6.0, "cycles": 2},
                   {"kind": "rates", "duration_s": 5.0, "turn_rate_deg_per_s": 5.0, "accel_m_per_s2": 2.0}])
    _assert_smooth(tr, 200.0)
    assert np.linalg.norm(tr["vel_enu"][-1]) == pytest.approx(200.0 + 2.0 * 4.0, abs=1e-6)


@pytest.mark.parametrize("segment,key,text", [
    ({"kind": "turn", "angle_deg": 90.0}, "segment[0].rate_deg_per_s", "exactly one of"),
    ({"kind": "turn", "rate_deg_per_s": 3.0, "angle_deg": 90, "bogus": 1}, "segment[0].bogus", "unknown key"),
    ({"kind": "cruise", "duration_s": -2.0}, "segment[0].duration_s", "must be > 0, got -2.0"),
    ({"kind": "cruise", "duration_s": "long"}, "segment[0].duration_s", "expected a number"),
    ({"kind": "warp", "duration_s": 1.0}, "segment[0].kind", "must be one of"),
    ({"kind": "static", "duration_s": 1.0}, "segment[0].kind", "needs speed 0"),
])
def test_bad_segments_name_the_key(segment, key, text):
    with pytest.raises(ScenarioError) as err:
        _run([segment])
    assert f"trajectory.{key}" in str(err.value) and text in str(err.value)


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")  # quad at its roundoff limit
@pytest.mark.parametrize("duration,ramp,period", [(12.0, 1.0, 6.0), (7.3, 2.1, 2.5), (0.8, 0.4, 6.0),
                                                  (10.0, 5.0, 3.3), (3.0, 1.0, 0.07)])
def test_weave_heading_change_closed_form_matches_quadrature(duration, ramp, period):
    from scipy.integrate import quad

    from simkit.trajectory.profiles import Sinusoid

    w = Sinusoid(2.0, duration, min(ramp, duration / 2), 0.3, period)
    breaks = np.arange(w.start, w.end, period / 4)[1:]
    ref, err = quad(lambda t: w.evaluate(t)[0], w.start, w.end, points=breaks, limit=2000, epsabs=1e-15)
    assert w.integral() == pytest.approx(ref, abs=1e-14 + 10 * err)


def test_weave_then_waypoints_enter_along_the_flown_heading():
    """The planner's heading after a weave (closed form) is the one the generator flies, so the waypoint spline
    starts along the actual velocity: no step in the body rate at the join."""
    sc, tr = _run([{"kind": "weave", "heading_amplitude_deg": 25.0, "period_s": 7.0, "cycles": 1.3},
                   {"kind": "waypoints", "points_enu_m": [[1000.0, 1500.0, 0.0], [3000.0, 2000.0, 0.0]]}])
    _assert_smooth(tr, 200.0)
