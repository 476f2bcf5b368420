"""GNSS error models against authorities: RTKLIB (ionmodel, tropmodel, frequencies), allantools, closed forms."""
import numpy as np

from simkit.gnss import atmosphere, clock, dd_covariance, noise, signals

import pyrtklib as rtk


def _arr(values):
    a = rtk.Arr1Ddouble(len(values))
    for i, v in enumerate(values):
        a[i] = float(v)
    return a


def test_signal_frequencies_match_rtklib():
    f = {s.name: s.freq_hz for s in signals.SIGNALS.values()}
    assert f["L1C"] == rtk.FREQ1 and f["L2W"] == rtk.FREQ2 and f["L5Q"] == rtk.FREQ5
    assert f["B1I"] == rtk.FREQ1_CMP and f["B3I"] == rtk.FREQ3_CMP
    assert f["B1C"] == rtk.FREQ1 and f["B2a"] == rtk.FREQ5  # BDS-3 B1C / B2a share L1 / L5
    assert signals.get("B1I").rinex_codes() == ("C2I", "L2I", "D2I", "S2I")


def test_klobuchar_gps_matches_rtklib_ionmodel():
    rng = np.random.default_rng(0)
    alpha, beta = atmosphere.DEFAULT_GPS_ALPHA, atmosphere.DEFAULT_GPS_BETA
    ion = _arr(list(alpha) + list(beta))
    worst = 0.0
    for _ in range(300):
        lat, lon = rng.uniform(-1.4, 1.4), rng.uniform(-np.pi, np.pi)
        az, el = rng.uniform(0, 2 * np.pi), rng.uniform(0.05, np.pi / 2)
        sow = rng.uniform(0, 604800)
        ref = rtk.ionmodel(rtk.gpst2time(2416, sow), ion, _arr([lat, lon, 100.0]), _arr([az, el]))
        ours = atmosphere.klobuchar_gps(alpha, beta, lat, lon, az, el, sow)
        worst = max(worst, abs(ours - ref))
    print(f"\nKlobuchar GPS vs RTKLIB ionmodel: max |diff| {worst:.2e} m over 300 geometries")
    assert worst < 1e-6


def test_saastamoinen_matches_rtklib_tropmodel():
    rng = np.random.default_rng(1)
    worst = 0.0
    for _ in range(200):
        lat, h, el = rng.uniform(-1.4, 1.4), rng.uniform(0, 5000), rng.uniform(0.1, np.pi / 2)
        ref = rtk.tropmodel(rtk.gpst2time(2416, 0.0), _arr([lat, 0.3, h]), _arr([0.0, el]), 0.5)
        ours = atmosphere.troposphere(lat, h, el)
        worst = max(worst, abs(ours - ref))
    print(f"\nSaastamoinen vs RTKLIB tropmodel: max |diff| {worst:.2e} m")
    assert worst < 1e-6


def test_klobuchar_bds_daytime_shape():
    """BDS-SIS-ICD-B1I: night-time floor 5 ns (x obliquity), peak at 14:00 local time at the pierce point."""
    a, b = atmosphere.DEFAULT_BDS_ALPHA, atmosphere.DEFAULT_BDS_BETA
    lat, lon = np.radians(34.0), 0.0
    tod = np.arange(0, 86400, 60.0)
    zen = atmosphere.klobuchar_bds(a, b, lat, lon, 0.0, np.pi / 2, tod)
    assert np.isclose(zen.min(), 5e-9 * 299792458.0)
    assert abs(tod[np.argmax(zen)] - 50400.0) <= 60.0


def test_clock_allan_deviation_matches_h_coefficients():
    import allantools
    for name in ("tcxo", "ocxo"):
        osc = clock.PRESETS[name]
        proc = clock.ClockProcess(osc, 1.0, np.random.default_rng(5))
        bias, _ = proc.advance(200_000)
        taus = np.array([1.0, 10.0, 100.0, 1000.0])
        t2, adev, err, n = allantools.oadev(bias, rate=1.0, data_type="phase", taus=taus)
        theory = np.sqrt(clock.allan_variance(osc, t2))
        print(f"\n{name}: tau {t2} ADEV {adev} theory {theory}")
        assert np.all(np.abs(adev / theory - 1) < 0.15)


def test_dd_covariance_closed_form():
    """Equal sigmas, one baseline: DD covariance = 2 sigma^2 (I + 1 1^T) (e.g. Teunissen & Kleusberg 1998)."""
    s = 0.003
    sigma = np.full((2, 6), s)
    ref = np.array([2, 2, 2, 2, 2, 2])
    valid = np.ones(6, bool)
    q, ant, sat = dd_covariance(sigma, ref, valid)
    assert list(sat) == [0, 1, 3, 4, 5] and set(ant) == {1}
    np.testing.assert_allclose(q, 2 * s**2 * (np.eye(5) + np.ones((5, 5))))


def test_tracking_jitter_scaling():
    """Thermal-noise jitter: at high C/N0 it falls as 10^(-C/N0 / 20) (the squaring loss vanishes); the
    squaring-loss factor makes low C/N0 worse than that; narrower correlators reduce the DLL jitter."""
    lam = signals.get("L1C").wavelength_m
    chip = signals.get("L1C").chip_length_m
    hi = np.array([60.0, 70.0])
    for f in (lambda c: noise.pll_sigma_m(c, lam, 15.0, 0.02), lambda c: noise.dll_sigma_m(c, chip, 1.0, 0.5, 0.02),
              lambda c: noise.fll_sigma_hz(c, 2.0, 0.02)):
        r = f(hi[1]) / f(hi[0])
        assert abs(r / 10 ** (-0.5) - 1) < 1e-3
        low = f(np.array([25.0, 35.0]))
        assert low[0] / low[1] > 10 ** 0.5
    assert noise.dll_sigma_m(40.0, chip, 1.0, 0.1, 0.02) < noise.dll_sigma_m(40.0, chip, 1.0, 1.0, 0.02)
