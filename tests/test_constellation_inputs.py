"""Bad input to the constellation API and the edges of its validity: fractional weeks, Kepler's equation that does
not converge, validity spans and the error for times no satellite covers."""
import numpy as np
import pytest
from scipy.optimize import brentq

from simkit import gpstime
from simkit.constellation import kepler, load
from simkit.constellation.errors import ConstellationInputError, NoStateError
from simkit.errors import SimkitError

from conftest import DATA

BRDM = "BRDM00DLR_S_20261170000_01D_MN.rnx.gz"  # 2026-04-27 (day 117), GPS + BDS
YUMA = DATA / "yuma" / "almanac.yuma.week0149.405504.txt"  # GPS week 2197, toa 405504 s


@pytest.mark.parametrize("week", [2300.7, np.array([2416.0, 2416.5]), np.nan, np.inf, "2416"])
def test_state_rejects_a_week_that_is_not_a_whole_number(week):
    c = load("nominal:gps")
    with pytest.raises(ConstellationInputError, match="gps_week: found .*expected an integer GPS week") as err:
        c.state(week, 0.0)
    assert isinstance(err.value, ValueError) and isinstance(err.value, SimkitError)


def test_whole_weeks_given_as_floats_are_accepted():
    c = load("nominal:gps")
    np.testing.assert_array_equal(c.state(2416.0, 3.0)[0], c.state(2416, 3.0)[0])
    np.testing.assert_array_equal(c.state(np.array([2416.0, 2417.0]), 3.0)[0],
                                  c.state(np.array([2416, 2417]), 3.0)[0])


def test_state_each_names_the_expected_shape():
    c = load("nominal:gps")
    with pytest.raises(ConstellationInputError, match=r"gps_sow: .*\(\.\.\., 24\)"):
        c.state_each(2416, np.zeros((3, 5)))


def _kepler_radius(a, e, m):
    """Radius a (1 - e cos E) with E from a bracketing root finder on Kepler's equation (the authority)."""
    m_red = np.mod(m + np.pi, 2 * np.pi) - np.pi
    ecc = brentq(lambda x: x - e * np.sin(x) - m_red, -np.pi, np.pi, xtol=1e-15, rtol=4 * np.finfo(float).eps)
    return a * (1.0 - e * np.cos(ecc))


def test_kepler_equation_is_solved_or_flagged_nan():
    """Newton from E = M solves every GNSS orbit; for e -> 1 it can oscillate: those entries are NaN, never a wrong
    position. Every finite result agrees with a bracketing solver."""
    c = kepler.COL
    grid = [(e, m) for e in (0.0, 0.01, 0.3, 0.7, 0.9, 0.99, 0.999) for m in np.linspace(-3.1, 3.1, 311)]
    table = kepler.empty_table(len(grid))
    table[:, c["sqrt_a"]] = np.sqrt(26559.7e3)
    table[:, c["mu"]] = 3.986005e14
    table[:, c["e"]] = [e for e, _ in grid]
    table[:, c["m0"]] = [m for _, m in grid]
    table[:, c["af0"]] = 1e-4
    idx = np.arange(len(grid))
    pos, clk, vel, drift = kepler.propagate(table, idx, np.zeros(len(grid)), velocity=True)
    bad = np.isnan(pos[:, 0])
    for out in (pos[:, 1], pos[:, 2], clk, vel[:, 0], drift):
        np.testing.assert_array_equal(np.isnan(out), bad)
    errors = [abs(np.linalg.norm(pos[k]) - _kepler_radius(26559.7e3, *grid[k])) for k in np.flatnonzero(~bad)]
    e = table[:, c["e"]]
    print(f"Kepler: {bad.sum()} of {len(grid)} (all with e >= {e[bad].min():.2f}) flagged NaN; the rest within "
          f"{max(errors) * 1e3:.2e} mm of a bracketing solver")
    assert max(errors) < 1e-6
    assert not bad[e <= 0.7].any() and bad.any()


def test_broadcast_validity_span_is_the_fit_interval_around_the_first_and_last_toe():
    c = load(BRDM, systems="GC")  # GPS and BDS: +-2 h / +-1 h about toe
    first, last = c.validity_span()
    assert first[0] == 2416 and last[0] == 2416
    # states exist just inside the span and nowhere just outside it
    for (week, sow), inside in ((first, 1.0), (last, -1.0)):
        assert np.isfinite(c.state(week, sow + inside)[0]).any()
        assert np.isnan(c.state(week, sow - inside)[0]).all()
        assert c.covered(week, sow + inside) and not c.covered(week, sow - inside)
    # the file holds day 117 (2026-04-27, GPS week 2416 day 1); fit intervals reach at most 2 h beyond it
    day = 86400.0
    assert day - 7200.0 <= first[1] <= day and 2 * day - 600.0 <= last[1] <= 2 * day + 7200.0
    # Galileo records hold for 4 h after their toe, GLONASS +-30 min about tb: the whole file's span
    gal, glo = load(BRDM, systems="E"), load(BRDM, systems="R")
    toe = gal.records.params[gal.records.healthy, 0] + gal.ref_week * 604800.0
    assert gpstime.diff_seconds(*gal.validity_span()[0], 0, 0.0) == toe.min()
    assert gpstime.diff_seconds(*gal.validity_span()[1], 0, 0.0) == toe.max() + 4 * 3600.0
    assert load(BRDM).validity_span() == (first, gal.validity_span()[1])
    tb = glo.records.params[glo.records.healthy, 0] + glo.ref_week * 604800.0
    assert gpstime.diff_seconds(*glo.validity_span()[1], 0, 0.0) == tb.max() + 1800.0


def test_almanac_span_is_the_copy_nearest_the_query_and_nominal_has_none():
    y = load(YUMA)
    first, last = y.validity_span(2197, 405504.0)
    toa = gpstime.diff_seconds(2197, 405504.0, 0, 0.0)
    assert gpstime.diff_seconds(*first, 0, 0.0) == pytest.approx(toa - 7 * 86400.0)
    assert gpstime.diff_seconds(*last, 0, 0.0) == pytest.approx(toa + 7 * 86400.0)
    assert y.covered(2197, 405504.0) and y.covered(2197 - 1024, 405504.0)  # 10-bit weeks: every copy
    assert not y.covered(2197 + 2, 405504.0)
    assert load("nominal:bds").validity_span() is None and load("nominal:bds").covered(9999, 0.0)


def test_times_no_satellite_covers_raise_one_error_naming_source_and_span():
    c = load(BRDM, systems="GC")
    with pytest.raises(NoStateError, match=r"BRDM.*no satellite has a state from 2026-04-29 23:59:42 UTC to 2026-04-30 00:58:42 UTC; "
                                           r"the source covers 2026-04-26 21:59:42 UTC to 2026-04-28 01:59:26 UTC") as err:
        c.require_states(2416, 4 * 86400.0 + np.arange(0.0, 3600.0, 60.0))  # Thursday 2026-04-30 00:00 GPST
    assert isinstance(err.value, ConstellationInputError) and err.value.span == c.validity_span()
    ok = c.require_states(2416, np.array([86400.0 * 1.5, 86400.0 * 4]))  # partly covered: a mask, no error
    np.testing.assert_array_equal(ok, [True, False])
