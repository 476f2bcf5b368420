"""C/N0 against elevation on the static IGS station SOLO (2016-01-15, 5 epochs) with almanac elevations
(docs/real_data.md, "A static station with C/N0").

SOLO has signal strengths but no navigation file of its day in shared/data; the nearest GPS almanacs are the
week-862 YUMA (t_oa 2016-03-02, 47 days after) and 20160331.alm (t_oa 2016-04-02, 78 days after). Steps:

1. How good is an almanac that far from its t_oa? Both almanacs propagated to 2016-06-06 (96 and 65 days) against
   that day's broadcast orbits (BRDC00WRD_U_20161580000): the elevation error at SOLO.
2. On SOLO's own epochs: the pseudorange minus the almanac range and clock, less a receiver clock per epoch (the
   median over satellites): the almanac's error along the line of sight, a direct check at the date.
3. SOLO's GPS C/N0 (S1C, S2W) per 10-degree elevation bin with the almanac elevations, against simkit's C/N0
   model (the defaults, and zenith C/N0 + rolloff + L2W offset fitted by least squares, fitted on the even PRNs and
   checked on the odd ones, and in sample).

Run: python benchmarks/solo_almanac.py [--obs OBS] [--almanac YUMA]
"""
import argparse
import json
from pathlib import Path

import numpy as np

from simkit import gpstime
from simkit.constellation import sources
from simkit.constellation.geometry import lines_of_sight_enu
from simkit.earth import C_LIGHT
from simkit.gnss import noise
from simkit.realdata import importer

ROOT = Path(__file__).resolve().parents[1]
BAD_KM = 50.0   # 50 km across a 20 000 km line of sight: 0.14 deg


def _elevations(sat_pos, rx):
    rxa = np.broadcast_to(np.asarray(rx, float), (sat_pos.shape[0], 3))
    with np.errstate(invalid="ignore"):
        return np.degrees(lines_of_sight_enu(rxa, sat_pos)[1])


def almanac_error_at(almanac, nav, rx, week, sows) -> dict:
    """Elevation error (deg) at ``rx`` of ``almanac`` propagated to GPS ``week``/``sows`` against the broadcast
    orbits of ``nav`` (satellites above 5 deg in the broadcast)."""
    alm, brdc = sources.load(almanac, validity_days=400), sources.load(nav, systems="G")
    cols = {s: i for i, s in enumerate(brdc.sat_ids)}
    pairs = [(i, cols[s]) for i, s in enumerate(alm.sat_ids) if s in cols]
    a = alm.state(np.full(sows.size, week), sows)[0][:, [i for i, _ in pairs]]
    b = brdc.state(np.full(sows.size, week), sows)[0][:, [j for _, j in pairs]]
    ea, eb = _elevations(a, rx), _elevations(b, rx)
    vis = eb > 5
    d = np.abs(ea - eb)[vis & np.isfinite(ea)]
    (w0, s0), (w1, s1) = alm.validity_span(week, sows.mean())
    toa = 0.5 * (w0 * 604800.0 + s0 + w1 * 604800.0 + s1)
    return {"almanac": Path(almanac).name, "days_from_toa": float((week * 604800.0 + sows.mean() - toa) / 86400.0),
            "toa_utc": str(gpstime.gps_to_utc(0, toa)),
            "satellite_epochs": int(vis.sum()), "median_deg": float(np.median(d)),
            "p95_deg": float(np.percentile(d, 95)), "share_within_0.5_deg": float(np.mean(d <= 0.5)),
            "position_error_median_km": float(np.nanmedian(np.linalg.norm(a - b, axis=-1)) / 1e3)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--obs", default=str(ROOT / "tests" / "data" / "rinex_obs" / "solo0150.16o"))
    ap.add_argument("--almanac", default=str(ROOT / "simkit" / "data" / "orekit_yuma_week0862.txt"))
    args = ap.parse_args()
    nav = ROOT / "simkit" / "data" / "BRDC00WRD_U_20161580000_01D_MN.rnx.gz"
    imp = importer.import_rinex(args.obs, [], None, None)
    d = imp.datasets
    rx = d["reference/pos_ecef"]
    out = {"almanac_accuracy": [almanac_error_at(a, nav, rx, 1900, 86400 + np.arange(0, 86400, 600.0))
                                for a in (args.almanac, ROOT / "simkit" / "data" / "20160331.alm")]}
    # SOLO's epochs with the almanac
    week, sow0 = int(imp.attrs["start_gps_week"]), float(imp.attrs["start_gps_sow"])
    sats = [str(s) for s in d["gnss/sat_id"]]
    gps = [i for i, s in enumerate(sats) if s.startswith("G")]
    alm = sources.load(args.almanac, validity_days=400)
    acol = {s: i for i, s in enumerate(alm.sat_ids)}
    gps = [i for i in gps if sats[i] in acol]
    t = d["gnss/t"]
    code = d["gnss/obs/L1C/code"][:, 0][:, gps]
    t_tx = sow0 + t[:, None] - np.nan_to_num(code, nan=0.075 * C_LIGHT) / C_LIGHT
    idx = [acol[sats[i]] for i in gps]
    full = np.repeat(t_tx[:, :1], len(alm.sat_ids), axis=1)
    full[:, idx] = t_tx
    pos, clk = alm.state_each(np.full(full.shape, week), full)
    pos, clk = pos[:, idx], clk[:, idx]
    # the Earth's rotation over the light time (Sagnac), to first order
    tau = np.linalg.norm(pos - rx, axis=-1) / C_LIGHT
    w = 7.2921151467e-5 * tau
    pos = np.stack([pos[..., 0] + w * pos[..., 1], pos[..., 1] - w * pos[..., 0], pos[..., 2]], axis=-1)
    rng = np.linalg.norm(pos - rx, axis=-1)
    res = code - rng + C_LIGHT * clk
    res = res - np.nanmedian(res, axis=1, keepdims=True)
    out["solo_range_residual"] = {"almanac": Path(args.almanac).name, "days_from_toa": -47.0,
                                  "rms_km": float(np.sqrt(np.nanmean(res ** 2)) / 1e3),
                                  "max_km": float(np.nanmax(np.abs(res)) / 1e3),
                                  "per_satellite_km": {sats[i]: round(float(np.nanmean(res[:, k])) / 1e3, 1)
                                                       for k, i in enumerate(gps) if np.isfinite(res[:, k]).any()}}
    # a satellite whose almanac range is off by more than BAD_KM (a manoeuvre since, or a PRN given to another
    # satellite) has no trustworthy elevation either: left out
    n_ok = np.isfinite(res).sum(0)
    bad = np.abs(np.nansum(res, axis=0) / np.maximum(n_ok, 1)) > BAD_KM * 1e3
    out["solo_range_residual"]["left_out"] = [sats[i] for k, i in enumerate(gps) if bad[k]]
    ok = np.abs(res[:, ~bad])
    out["solo_range_residual"]["rms_km_kept"] = float(np.sqrt(np.nanmean(ok ** 2)) / 1e3)
    pos[:, bad] = np.nan
    el = _elevations(pos, rx)
    cn0 = {s: d[f"gnss/obs/{s}/cn0"][:, 0][:, gps] for s in ("L1C", "L2W")}
    even = np.array([int(sats[i][1:]) % 2 == 0 for i in gps])
    default = {s: noise.cn0_dbhz(np.radians(90 - el), 45.0, 10.0, 0.0) for s in cn0}

    def fit(cols):
        x = ((90.0 - el[:, cols]) / 90.0) ** 2
        rows, ys = [], []
        for k, s in enumerate(cn0):
            ok = np.isfinite(cn0[s][:, cols]) & np.isfinite(x)
            rows.append(np.column_stack([np.ones(ok.sum()), -x[ok], np.full(ok.sum(), float(k))]))
            ys.append(cn0[s][:, cols][ok])
        return np.linalg.lstsq(np.vstack(rows), np.concatenate(ys), rcond=None)[0]

    def model(beta, k):
        return beta[0] - beta[1] * ((90.0 - el) / 90.0) ** 2 + beta[2] * k

    edges = np.arange(0, 91, 10)
    table = []
    beta_all, beta_even = fit(np.ones(len(gps), bool)), fit(even)
    for k, s in enumerate(cn0):
        for lo, hi in zip(edges[:-1], edges[1:]):
            m = np.isfinite(cn0[s]) & (el >= lo) & (el < hi)
            if not m.any():
                continue
            odd = m & ~even[None, :]
            table.append({"signal": s, "bin_deg": [int(lo), int(hi)], "n": int(m.sum()),
                          "satellites": int(m.any(0).sum()), "real_dbhz": round(float(cn0[s][m].mean()), 2),
                          "default_model": round(float(default[s][m].mean()), 2),
                          "fitted_in_sample": round(float(model(beta_all, k)[m].mean()), 2),
                          "odd_prns_real": round(float(cn0[s][odd].mean()), 2) if odd.any() else None,
                          "odd_prns_fitted_on_even": round(float(model(beta_even, k)[odd].mean()), 2)
                          if odd.any() else None})

    def rms(key, ref="real_dbhz", sig=None):
        v = [r[key] - r[ref] for r in table if r[key] is not None and (sig is None or r["signal"] == sig)]
        return round(float(np.sqrt(np.mean(np.square(v)))), 2) if v else None

    out["cn0"] = {"fit_in_sample": {"zenith_dbhz": round(float(beta_all[0]), 2), "rolloff_db": round(float(beta_all[1]), 2),
                                    "L2W_offset_db": round(float(beta_all[2]), 2)},
                  "fit_even_prns": [round(float(x), 2) for x in beta_even], "bins": table,
                  "rms_over_bins_dbhz": {s: {"default": rms("default_model", sig=s), "in_sample": rms("fitted_in_sample", sig=s),
                                             "odd_prns_out_of_sample": rms("odd_prns_fitted_on_even", "odd_prns_real", s)}
                                         for s in cn0},
                  "epochs": int(t.size), "utc_first": str(gpstime.gps_to_utc(week, sow0))}
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
