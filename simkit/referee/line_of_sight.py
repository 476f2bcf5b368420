"""Errors split by the line-of-sight state of the epochs (files simulated with an [environment]).

Each GNSS epoch gets one class from the signals the receiver tracked there (any antenna, any signal), the most
severe first: ``nlos`` (a satellite tracked by its reflection only), ``reflected`` (a reflection beside a direct
signal), ``direct`` (every tracked signal direct). An estimate's epoch takes the class of the latest GNSS epoch at
or before it. The statistics of each class are those of :func:`simkit.referee.stats.statistics`.
"""
from __future__ import annotations

import numpy as np

from ..io import gnss_signals, has, open_dataset, read_gnss
from . import stats

CLASSES = ("direct", "reflected", "nlos")


def epoch_classes(path):
    """``(t, cls, counts)`` of the file's GNSS epochs: times (M,) s, class index (M,) into :data:`CLASSES`, and
    the mean number of satellites per antenna in each state 0..3 over the epochs of each class {class: (4,)};
    None when the file has no /gnss/truth/los_state."""
    with open_dataset(path) as ds:
        if not has(ds, "gnss_truth", "los_state"):
            return None
        g = read_gnss(ds, obs=("code",), truth=("los_state",), satellites=False)
        sigs = gnss_signals(ds)
    state = g.truth["los_state"]                                           # (M, A, S)
    tracked = np.any([np.isfinite(g.obs["code"][s]) for s in sigs], axis=0)
    cls = np.where((tracked & (state == 2)).any(axis=(1, 2)), 2,
                   np.where((tracked & (state == 1)).any(axis=(1, 2)), 1, 0))
    counts = {}
    for k, name in enumerate(CLASSES):
        rows = cls == k
        counts[name] = [float((state[rows] == s).sum(axis=2).mean()) if rows.any() else float("nan")
                        for s in range(4)]
    return g.t, cls, counts


def by_state(path, err, series: dict) -> dict:
    """{class: {"epochs", "satellites_per_antenna": {state: mean}, "statistics": {quantity: stats}}} for the
    scored epochs ``err.t`` of the error ``series``; {} for a file without line-of-sight states."""
    found = epoch_classes(path)
    if found is None:
        return {}
    t, cls, counts = found
    k = np.clip(np.searchsorted(t, err.t + 1e-9, side="right") - 1, 0, t.size - 1)
    mine = cls[k]
    out = {}
    for c, name in enumerate(CLASSES):
        rows = mine == c
        if not rows.any():
            continue
        out[name] = {"epochs": int(rows.sum()),
                     "satellites_per_antenna": dict(zip(("direct", "direct+reflected", "nlos", "blocked"),
                                                        counts[name])),
                     "statistics": {q: stats.statistics(x[rows]) for q, x in series.items()}}
    return out
