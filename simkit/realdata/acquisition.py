"""When a real receiver first tracks a rising satellite: the acquisition delay of :mod:`simkit.gnss.acquisition`
fitted from a real file and its twin.

A satellite *rises* in the twin when the twin (simkit's defaults: tracked wherever the satellite is above the mask
and has a signal of the file) starts tracking it after the first epoch, cut by the fitted horizon profile when there
is one (the station's own mask: the crossing that matters). For each rising satellite the real file's first tracked
epoch at or after the crossing gives the delay (s, on the epoch grid: the crossing lies up to one interval before the
twin's first epoch) and the elevation there. The fitted ``delay_s`` is their median (0 when the receiver tracks the
satellites as they cross, or none rises); a rising satellite the real receiver never tracks in the file is counted,
not used. The visibility agreement with and without the model is computed on the same grid by the simulator's own
rule (:class:`simkit.gnss.acquisition.Acquisition`), so that the report shows what the model buys.
"""
from __future__ import annotations

import numpy as np

from ..gnss.acquisition import Acquisition, AcquisitionConfig
from . import horizon


def rising_satellites(t, el, twin_on, real_on) -> list[dict]:
    """[{column, t_visible_s, delay_s, elevation_deg (at the first real track) or None}] for every run of
    ``twin_on`` (M, S) that starts after the first epoch; ``el`` (M, S) rad, ``real_on`` (M, S)."""
    out = []
    prev = np.concatenate([np.ones((1, twin_on.shape[1]), bool), twin_on[:-1]])
    for k, s in zip(*np.nonzero(twin_on & ~prev)):
        end = k + int(np.argmin(twin_on[k:, s])) if not twin_on[k:, s].all() else twin_on.shape[0]
        hit = np.flatnonzero(real_on[k:end, s])
        first = k + int(hit[0]) if hit.size else None
        out.append({"column": int(s), "t_visible_s": float(t[k]),
                    "delay_s": None if first is None else float(t[first] - t[k]),
                    "elevation_deg": None if first is None else float(np.degrees(el[first, s])),
                    "elevation_at_crossing_deg": float(np.degrees(el[k, s]))})
    return out


def fit(t, el, az, twin_on, real_on, mask_deg: float, table: dict | None = None) -> dict:
    """The acquisition fit of a real file on its twin's grid: ``t`` (M,) s, ``el``/``az`` (M, S) rad of the twin's
    geometry, ``twin_on`` the default twin's tracking, ``real_on`` the real one (M, S) bool, ``table`` the horizon
    profile (:func:`.horizon.mask_table`) or None: {delay_s, rising [...], untracked, agreement_without,
    agreement_with}."""
    visible = twin_on & ~horizon.below(el, az, table) if table is not None else twin_on.copy()
    rising = rising_satellites(t, el, visible, real_on)
    delays = [r["delay_s"] for r in rising if r["delay_s"] is not None]
    delay = float(np.median(delays)) if delays else 0.0
    with np.errstate(invalid="ignore"):
        above = el >= np.radians(mask_deg)
    acq = Acquisition(AcquisitionConfig(delay_s=delay), 1, el.shape[1])
    modelled = acq.apply(t, visible[:, None, :], el[:, None, :])[:, 0, :]

    def agree(pred):
        return float(np.mean(real_on[above] == pred[above])) if above.any() else None

    return {"delay_s": delay, "rising": rising, "used": len(delays), "untracked": len(rising) - len(delays),
            "agreement_without": agree(visible), "agreement_with": agree(modelled)}


def report_lines(result: dict | None) -> list[str]:
    """The report.md section of :func:`fit` (none without a fit)."""
    if not result:
        return []
    out = ["", "## Acquisition of rising satellites", "",
           f"Fitted delay_s = {result['delay_s']:.0f} s (median over {result['used']} rising satellites; "
           f"{result['untracked']} rising in the twin but never tracked by the receiver in the file). Visibility "
           f"agreement on the default twin's grid without / with the model: "
           f"{100 * (result['agreement_without'] or 0):.2f} % / {100 * (result['agreement_with'] or 0):.2f} %.", "",
           "| satellite | in view at (s) | elevation there (deg) | first tracked after (s) | at elevation (deg) |",
           "|---|---:|---:|---:|---:|"]
    for r in result["rising"]:
        out.append(f"| {r.get('sat', r.get('column'))} | {r['t_visible_s']:.0f} | {r['elevation_at_crossing_deg']:.1f} | "
                   + ("never | - |" if r["delay_s"] is None else f"{r['delay_s']:.0f} | {r['elevation_deg']:.1f} |"))
    return out
