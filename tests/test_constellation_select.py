"""Record selection (compiled, all satellites at once) against its rule applied record by record: the healthy
record with the nearest toe (the later on a tie) whose validity covers t; Galileo's after-toe records: the latest
toe strictly before t within the validity; repeating almanac records: the copy nearest to t."""
import numpy as np
import pytest

from simkit.constellation import load


def _last_in_order(rows, toe, candidates):
    """Of records with one toe, the last in the file's order (a re-broadcast with the same toe replaces one)."""
    return candidates[np.argmax(rows[candidates])]


def _rule(const, t):
    r = const.records
    toe_all = r.params[:, 0]
    idx = np.full(t.shape, -1, dtype=np.int64)
    t_eval = np.array(t, dtype=float)
    for s in range(t.shape[1]):
        rows = np.flatnonzero((r.sat == s) & r.healthy)
        if rows.size == 0:
            continue
        toe, half = toe_all[rows], r.half_width[rows]
        period = r.period[rows[0]] if r.period is not None else np.inf
        after = r.after_toe is not None and bool(r.after_toe[rows].all())
        for n in range(t.shape[0]):
            x = t[n, s]
            if np.isfinite(period):
                x -= period * np.round((x - toe.min()) / period)
                t_eval[n, s] = x
            if not np.isfinite(x):
                continue
            if after:
                before = np.flatnonzero(toe < x)
                if before.size:
                    latest = before[toe[before] == toe[before].max()]
                    pick = _last_in_order(rows, toe, latest)
                    if x - toe[pick] <= half[pick]:
                        idx[n, s] = rows[pick]
                continue
            dist = np.abs(x - toe)
            # the nearest toe (the later one on a tie, the last in file order among equal toes), if its own
            # validity covers t
            nearest = np.flatnonzero(dist == dist.min())
            nearest = nearest[toe[nearest] == toe[nearest].max()]
            pick = _last_in_order(rows, toe, nearest)
            if dist[pick] <= half[pick]:
                idx[n, s] = rows[pick]
    return idx, t_eval


@pytest.mark.parametrize("source", ["BRDM00DLR_S_20261170000_01D_MN.rnx.gz", "almanac.yuma.week0278.061440.txt"])
def test_selection_follows_the_rule_at_edges_ties_and_gaps(source):
    const = load(source)
    const = next(p for p in getattr(const, "parts", [const]) if hasattr(p, "records") and p.kind != "glonass") \
        if hasattr(const, "parts") else const
    rs = np.random.default_rng(1)
    toe = const.records.params[:, 0]
    half = np.minimum(const.records.half_width, 1e7)
    edges = np.concatenate([toe, toe + half, toe - half, 0.5 * (np.sort(toe)[:-1] + np.sort(toe)[1:])])
    n_sat = len(const.sat_ids)
    t = rs.choice(edges, (300, n_sat)) + rs.choice([0.0, 1e-9, -1e-9, 0.5, -0.5, 3600.0, 1e5, np.nan], (300, n_sat))
    got, want = const.select(t), _rule(const, t)
    assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1], equal_nan=True)
    assert 0.2 < (got[0] >= 0).mean() < 1.0
