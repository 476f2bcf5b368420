"""Doppler against the time-differenced carrier on every moving bundled scenario, every error term and the
oscillator on: the Doppler must be the exact rate of everything the carrier contains except its random parts.

The carrier minus its stored random terms (thermal noise, multipath) and receiver clock, differenced over two
epochs at 100 Hz, is compared with Simpson's rule over the Doppler minus its noise draw and clock drift:
Simpson's error is O(dt^4) (below 1e-6 m/s here), so any difference is a missing or wrong rate term.
"""
import numpy as np
import pytest

import simkit
from simkit.earth import C_LIGHT

CASES = {  # scenario -> (seconds simulated, what happens in them)
    "quickstart": 60.0,        # car: acceleration, 90 deg turn, weave
    "high_dynamic": 120.0,     # 5-7 g turns, 250 deg/s rolls, dives at 245 m/s
    "airborne_stim300": 150.0,  # take-off run and climb
}


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(CASES))
def test_doppler_is_the_carrier_rate_with_every_error_term(tmp_path, name):
    path = simkit.run(name, out=tmp_path / "d.h5",
                      overrides=[f"scenario.duration_s={CASES[name]}", "gnss.rate_hz=100.0",
                                 "gnss.slip_rate_per_h=0.0"])
    worst = 0.0
    with simkit.open(path) as ds:
        dt = 1.0 / ds.rate_hz("gnss")
        clock = ds["gnss/truth/receiver_clock"][:][..., None]
        drift = ds["gnss/truth/receiver_clock_drift"][:][..., None]
        for sig, lam in zip(ds["gnss/signals"][:], C_LIGHT / ds["gnss/frequency_hz"][:]):
            truth = f"gnss/truth/{sig}"
            phase = (ds[f"gnss/obs/{sig}/carrier"][:] * lam - ds[f"{truth}/noise_carrier"][:]
                     - ds[f"{truth}/multipath_carrier"][:] - clock)              # m, ambiguity kept
            rate = (-ds[f"gnss/obs/{sig}/doppler"][:] * lam + ds[f"{truth}/noise_doppler"][:] * lam
                    - drift)                                                     # d(phase)/dt, m/s
            lli = ds[f"gnss/obs/{sig}/lli"][:]
            dphase = phase[2:] - phase[:-2]
            simpson = dt / 3.0 * (rate[:-2] + 4.0 * rate[1:-1] + rate[2:])
            ok = (lli[1:-1] == 0) & (lli[2:] == 0)
            err = np.where(ok, dphase - simpson, np.nan) / (2.0 * dt)
            assert np.isfinite(err).sum() > 1000
            worst = max(worst, float(np.nanmax(np.abs(err))))
        iono = max(_rate_closure(ds[f"gnss/truth/{s}/ionosphere"][:], ds[f"gnss/truth/{s}/ionosphere_rate"][:], dt)
                   for s in ds["gnss/signals"][:])
        trop = _rate_closure(ds["gnss/truth/troposphere"][:], ds["gnss/truth/troposphere_rate"][:], dt)
    print(f"\n{name}: max |Doppler - carrier rate| = {worst * 1e3:.4f} mm/s; ionosphere rate {iono:.1e} m/s, "
          f"troposphere rate {trop:.1e} m/s")
    assert worst < 1e-3
    assert iono < 1e-6      # the rate follows the pierce point as the receiver moves
    assert trop < 1e-5      # height and elevation terms; the latitude term (< 1e-5 m/s) is left out


def _rate_closure(x, rate, dt) -> float:
    """Max |(x[k+1] - x[k-1]) / 2 dt - Simpson mean of rate| over the record."""
    err = (x[2:] - x[:-2] - dt / 3.0 * (rate[:-2] + 4.0 * rate[1:-1] + rate[2:])) / (2.0 * dt)
    return float(np.nanmax(np.abs(err)))
