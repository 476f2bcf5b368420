"""gnss-lib-py's ``simulate_measures`` timed on its own: seconds per (epoch, satellite) for the code and Doppler of
one static GPS receiver. Imports only numpy and gnss-lib-py, so it runs in whatever interpreter has gnss-lib-py.

gnss-lib-py 1.1 pins pandas < 3, xarray <= 2024.7.0 and georinex <= 1.16.1; installed beside the tests' peers it
downgrades them and breaks tests, so it lives in its own environment
(``python -m venv /opt/glp && /opt/glp/bin/pip install gnss-lib-py``) and ``bench_gnss.py`` calls this file with
that interpreter (``GNSS_LIB_PY_PYTHON=/opt/glp/bin/python``).

Usage: ``python peer_gnss_lib_py.py NAV X Y Z GPS_MS EPOCHS`` (NAV an uncompressed RINEX navigation file, the
receiver at ECEF X, Y, Z m, the first epoch in GPS milliseconds since 1980-01-06); prints the seconds per
(epoch, satellite).
"""
import sys
import time
import warnings

import numpy as np


def main(nav, x, y, z, ms0, epochs):
    from gnss_lib_py.navdata.navdata import NavData
    from gnss_lib_py.parsers.rinex_nav import RinexNav
    from gnss_lib_py.utils.gnss_models import simulate_measures

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ephem = RinexNav(nav, satellites=[f"G{k:02d}" for k in range(1, 33)])
    state = NavData()
    for name, v in zip(("x_rx_m", "y_rx_m", "z_rx_m", "vx_rx_mps", "vy_rx_mps", "vz_rx_mps", "b_rx_m",
                        "b_dot_rx_mps"), [x, y, z] + [0.0] * 5):
        state[name] = np.array([v])
    rng = np.random.default_rng(0)
    n_sv = 0
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for k in range(epochs):
            meas, _ = simulate_measures(ms0 + 1000.0 * k, state, ephem=ephem, rng=rng, el_mask=10.0)
            n_sv += len(meas)
    return (time.perf_counter() - t0) / max(n_sv, 1)


if __name__ == "__main__":
    a = sys.argv[1:]
    print(main(a[0], float(a[1]), float(a[2]), float(a[3]), float(a[4]), int(a[5])))
