"""The plugin runner: samples reach a filter in time order with GNSS epochs after the IMU samples up to their
time; bad filters are named; pyins' loosely coupled filter (a third-party filter in NED / forward-right-down
conventions, examples/pyins_loosely_coupled.py) runs end to end on airborne_stim300 and is scored."""
import json
import sys

import numpy as np
import pytest

import simkit
from simkit import referee
from simkit.solution import Solution

from cli_errors import ROOT, run_cli


@pytest.fixture(scope="module")
def air(tmp_path_factory):
    return simkit.run("airborne_stim300", out=tmp_path_factory.mktemp("plugin") / "air.h5",
                      overrides=["scenario.duration_s=40"])


class Recorder:
    """A 'filter' that reports the truth it was started with at every GNSS epoch and records the call order."""

    def __init__(self):
        self.calls, self.t, self.init = [], [], None

    def start(self, init):
        self.init = init

    def predict(self, imu):
        self.calls.append(("imu", imu.t, imu.dt))

    def update(self, gnss):
        self.calls.append(("gnss", gnss.t, gnss.code["L1C"].shape))
        self.t.append(gnss.t)

    def solution(self):
        n = len(self.t)
        return Solution(t=np.array(self.t), pos_ecef=np.tile(self.init.pos_ecef, (n, 1)))


def test_runner_feeds_samples_in_time_order_and_scores(air):
    rec = Recorder()
    res = referee.run_filter(rec, air, duration_s=10.0)
    imu = [c for c in rec.calls if c[0] == "imu"]
    gnss = [c for c in rec.calls if c[0] == "gnss"]
    assert len(imu) == 1001 and len(gnss) == 11 and res.timing["imu_samples"] == 1001
    assert all(c[2] == pytest.approx(0.01) for c in imu)
    times = [c[1] for c in rec.calls]
    assert times == sorted(times)                          # each epoch after the IMU samples up to its time
    assert gnss[0][2][0] == 3                              # (A, S) per signal: three antennas
    # the vehicle stands still for the first 20 s: a frozen initial position has zero error
    assert res.score.statistics["position_3d"]["max"] < 1e-6


@pytest.mark.parametrize("block", [1, 4, 11])
def test_block_reading_gives_the_same_calls(air, monkeypatch, block):
    """The file is streamed in blocks of GNSS epochs: blocks of 1, 4 (0-3, 4-7, 8-10) or exactly all 11 epochs
    feed the filter exactly as one large block does."""
    whole = Recorder()
    referee.run_filter(whole, air, duration_s=10.0)
    from simkit.referee import plugin

    monkeypatch.setattr(plugin, "BLOCK_EPOCHS", block)
    blocks = Recorder()
    res = referee.run_filter(blocks, air, duration_s=10.0)
    assert blocks.calls == whole.calls and res.timing["gnss_epochs"] == 11


def test_a_filter_without_the_interface_is_named(air):
    with pytest.raises(referee.RefereeInputError, match="object has no predict, update, solution method"):
        referee.run_filter(object(), air)


@pytest.mark.slow   # pyins' batch filter runs in pandas: about 10 s for 40 s of data
def test_pyins_loosely_coupled_end_to_end(air, tmp_path, capfd):
    sys.path.insert(0, str(ROOT / "examples"))
    from pyins_loosely_coupled import PyinsLooselyCoupled, write_native_csv

    flt = PyinsLooselyCoupled()
    res = referee.run_filter(flt, air)
    # the batch filter (a minute on the whole file) is announced, not a silent wait
    assert "pyins: run_feedback_filter over 4001 IMU samples and 41 fixes ..." in capfd.readouterr().err
    sc = res.score
    assert sc.meta["epochs_scored"] == 40
    # metre-level code fixes with their ionospheric delay: metres horizontally, a few tenths of a degree
    assert sc.statistics["horizontal"]["rms"] < 10.0
    assert sc.statistics["heading"]["rms"] < 1.0 and sc.statistics["roll"]["rms"] < 1.0
    assert sc.nees["states"] == ["pos_n", "pos_e", "pos_d", "vel_n", "vel_e", "vel_d", "roll", "pitch", "heading"]
    assert res.timing["solution_s"] > 0 and res.solution.config["fixes"] == 41
    assert sc.nis["epochs"] == 40 and sc.nis["dof_mean"] == 3.0          # pyins' standardised innovations
    # pyins' native NED output as a CSV, scored from the command line, gives the plugin's numbers
    write_native_csv(tmp_path / "pyins.csv", *flt.native)
    out = run_cli(["score", str(air), "pyins.csv", "--spec", str(ROOT / "examples" / "spec_airborne.toml"),
                   "--json", "s.json"], tmp_path)
    assert out.returncode in (0, 1) and "## Checks" in out.stdout, out.stderr
    csv_stats = json.loads((tmp_path / "s.json").read_text())["statistics"]
    for q in ("horizontal", "up", "velocity_3d", "pitch", "roll", "heading"):
        assert csv_stats[q]["rms"] == pytest.approx(sc.statistics[q]["rms"], rel=1e-6, abs=1e-6), q
    nis = json.loads((tmp_path / "s.json").read_text())["nis"]
    assert nis["epochs"] == sc.nis["epochs"] and nis["mean"] == pytest.approx(sc.nis["mean"], rel=1e-6)


@pytest.mark.slow   # 120 s at 100 Hz through pyins: about 5 s
def test_pyins_strapdown_of_an_ideal_imu_reproduces_the_truth(tmp_path):
    """The conventions converter on a peer: pyins' own strapdown integration (NED, forward-right-down, degrees)
    of simkit's error-free IMU output, converted back by solution_from_ned, lands on simkit's truth."""
    import pandas as pd
    from pyins import strapdown

    from simkit import frames

    sys.path.insert(0, str(ROOT / "examples"))
    from pyins_loosely_coupled import PyinsLooselyCoupled

    path = simkit.run("airborne_stim300", out=tmp_path / "ideal.h5",
                      overrides=["scenario.duration_s=120", "imu.preset='ideal'"])
    truth = referee.read_truth(path)
    with simkit.open(path) as ds:
        t, gyro, accel = ds["imu/t"][:], ds["imu/gyro"][:], ds["imu/accel"][:]
        lever = ds["gnss/antennas/lever_arm_b"][:]
    wrapper = PyinsLooselyCoupled()
    wrapper.start(referee.TrueInitialState(0.0, truth.pos_ecef[0], truth.vel_enu[0], truth.quat_nb[0], lever, 0, 0.0))
    imu = pd.DataFrame(np.hstack([frames.enu_to_ned(gyro), frames.enu_to_ned(accel)]), index=t,
                       columns=["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"])
    integrator = strapdown.Integrator(wrapper.initial_pva(t[0]))
    integrator.integrate(strapdown.compute_increments_from_imu(imu, "rate"))
    tr = integrator.trajectory.iloc[::50]
    sol = referee.solution_from_ned(tr.index.values, np.radians(tr.lat.values), np.radians(tr.lon.values),
                                    tr.alt.values, vel_ned=tr[["VN", "VE", "VD"]].values,
                                    roll=np.radians(tr.roll.values), pitch=np.radians(tr.pitch.values),
                                    heading=np.radians(tr.heading.values))
    st = referee.score(truth, sol).statistics
    # 120 s including the take-off run and rotation: pyins' gravity model and integration differ from simkit's
    # truth generation at the cm / mm/s level; any convention slip (a swapped axis, a sign) gives metres and degrees
    assert st["horizontal"]["max"] < 0.05 and st["up"]["max"] < 0.5 and st["velocity_3d"]["max"] < 0.02
    assert max(st[q]["max"] for q in ("pitch", "roll", "heading")) < 1e-3        # degrees


@pytest.mark.slow   # both filters over 40 s of airborne_stim300; pyins' batch filter dominates
def test_simkit_kf15_and_pyins_side_by_side_through_the_plugin(air):
    """The same interface, the same file, the same referee: simkit's KF15 and pyins' loosely coupled filter.
    Both fix code-only positions with the ionosphere left in, so metre-level position errors are expected;
    simkit's filter carries its error-state covariance, whose NEES the referee evaluates."""
    sys.path.insert(0, str(ROOT / "examples"))
    from pyins_loosely_coupled import PyinsLooselyCoupled
    from simkit_kf15 import SimkitKf15

    ours = referee.run_filter(SimkitKf15(), air)
    theirs = referee.run_filter(PyinsLooselyCoupled(), air)
    rows = []
    for name, res in (("simkit KF15", ours), ("pyins", theirs)):
        st = res.score.statistics
        rows.append(f"{name:12s} RMS horizontal {st['horizontal']['rms']:.2f}, up {st['up']['rms']:.2f}, "
                    f"velocity {st['velocity_3d']['rms']:.3f}, heading {st['heading']['rms']:.3f} "
                    f"(units of simkit.referee.stats.UNIT_OF); {res.timing['total_s']:.1f} s")
    print("\n" + "\n".join(rows))
    assert ours.score.nees is not None and ours.score.nees["dof_mean"] == 9.0
    for res in (ours, theirs):
        st = res.score.statistics
        assert st["horizontal"]["rms"] < 20.0 and st["velocity_3d"]["rms"] < 2.0
