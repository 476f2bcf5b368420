"""The two-evaluation light-time solution of ``receiver_view`` against the light-time equation solved to
convergence, tau = |R_z(Omega_e tau) r(t - tau) - rx| / c, with a full broadcast evaluation per iteration.

The two differ by the rounding of the emission time in seconds of week (2.9e-11 s at 1.7e5 s, 0.1 um at 3.9
km/s), which the reference evaluates at and the solution's last step along the velocity does not."""
import numpy as np
import pytest

from simkit import frames, gpstime
from simkit.constellation import load
from simkit.constellation import geometry
from simkit.constellation.geometry import _rotate_z, receiver_view
from simkit.earth import C_LIGHT, OMEGA_E

BRDM = "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"


def _converged(const, rx, week, sow):
    """Fixed-point iteration on full broadcast states until the light time moves by < 1e-16 s."""
    m, s = sow.size, len(const.sat_ids)
    week_ms = np.broadcast_to(week[:, None], (m, s))
    tau = np.full((m, s), 0.075)
    for _ in range(10):
        tw, ts = gpstime.add_seconds(week_ms, sow[:, None], -tau)
        pos = const.state_each(tw, ts)[0]
        new = np.linalg.norm(_rotate_z(pos, OMEGA_E * tau) - rx[:, None, :], axis=-1) / C_LIGHT
        new = np.where(np.isfinite(new), new, 0.075)
        done = np.nanmax(np.abs(new - tau)) < 1e-16
        tau = new
        if done:
            break
    tw, ts = gpstime.add_seconds(week_ms, sow[:, None], -tau)
    pos, clk = const.state_each(tw, ts)
    return pos, clk, np.linalg.norm(_rotate_z(pos, OMEGA_E * tau) - rx[:, None, :], axis=-1)


@pytest.mark.parametrize("systems", ["G,C", "E,J", "R"])
def test_light_time_solution_equals_the_converged_light_time_equation(systems):
    const = load(BRDM, systems=systems)
    rs = np.random.default_rng(0)
    n = 400
    # receivers on the ground and in the air, over the file's day and its validity edges
    lat, lon = rs.uniform(-1.4, 1.4, n), rs.uniform(-3.1, 3.1, n)
    rx = frames.lla_to_ecef(lat, lon, rs.uniform(0.0, 12e3, n))
    sow = 86400.0 + np.sort(rs.uniform(-7200.0, 86400.0 + 7200.0, n))
    week = np.full(n, 2416)
    geo = receiver_view(const, rx, week, sow, velocity=True)
    pos, clk, rng = _converged(const, rx, week, sow)
    known = np.isfinite(pos[..., 0])
    assert np.array_equal(known, np.isfinite(geo.sat_pos_emission[..., 0])) and known.sum() > 1000
    dp = np.abs(geo.sat_pos_emission - pos)[known].max()
    dr = np.abs(geo.range - rng)[known].max()
    dc = np.abs(geo.sat_clock - clk)[known].max()
    print(f"\n{systems}: max |position| {dp:.1e} m, |range| {dr:.1e} m, |clock| {dc:.1e} s")
    assert dp < 3e-7 and dr < 1e-7 and dc < 1e-15   # range: 5e-7 cycles at L1


@pytest.mark.parametrize("systems", ["G,C", "E,J"])
def test_dense_epochs_started_from_interpolated_states_equal_the_converged_equation(systems):
    """1 Hz epochs of a receiver flying at 250 m/s across the GPS and BDS record changes at 01:00 and 00:30/01:30
    GPST (a record switching between the broadcast evaluations at reception): the states that start the iteration
    are interpolated (geometry.RECEPTION_GRID_S), the result still that of the converged equation."""
    const = load(BRDM, systems=systems)
    n = 3900
    sow = 86400.0 + 1500.0 + np.arange(n, dtype=float)          # 00:25 to 01:30 GPST

    lat = np.radians(34.2) + np.arange(n) * 250.0 / 6.37e6
    rx = frames.lla_to_ecef(lat, np.full(n, np.radians(108.9)), np.full(n, 9000.0))
    week = np.full(n, 2416)
    evaluated = []
    state_each = const.state_each
    const.state_each = lambda w, s, velocity=False: evaluated.append(np.shape(s)) or state_each(w, s, velocity)
    geo = receiver_view(const, rx, week, sow, velocity=True, reception_grid=True)
    const.state_each = state_each
    assert evaluated[0][0] == n // geometry.RECEPTION_GRID_S + 1    # the grid, not every epoch
    pos, clk, rng = _converged(const, rx, week, sow)
    known = np.isfinite(pos[..., 0])
    assert np.array_equal(known, np.isfinite(geo.sat_pos_emission[..., 0])) and known.sum() > 10 * n
    dp = np.abs(geo.sat_pos_emission - pos)[known].max()
    dr = np.abs(geo.range - rng)[known].max()
    dc = np.abs(geo.sat_clock - clk)[known].max()
    print(f"\n{systems}: max |position| {dp:.1e} m, |range| {dr:.1e} m, |clock| {dc:.1e} s")
    assert dp < 3e-7 and dr < 1e-7 and dc < 1e-15


def test_without_the_grid_every_epoch_starts_from_its_own_state():
    """The default (sparse epochs: `simkit sky`, imports): the states at reception are evaluated at the epochs."""
    const = load(BRDM, systems="G")
    sow = 86400.0 + 600.0 * np.arange(20)
    rx = np.broadcast_to(frames.lla_to_ecef(np.radians(34.2), np.radians(108.9), 400.0), (20, 3))
    evaluated = []
    state_each = const.state_each
    const.state_each = lambda w, s, velocity=False: evaluated.append(np.shape(s)) or state_each(w, s, velocity)
    plain = receiver_view(const, rx, np.full(20, 2416), sow, velocity=True)
    const.state_each = state_each
    assert evaluated[0][0] == 20
    grid = receiver_view(const, rx, np.full(20, 2416), sow, velocity=True, reception_grid=True)
    assert np.nanmax(np.abs(plain.range - grid.range)) < 1e-7
