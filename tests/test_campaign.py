"""simkit.campaign: statistics against scipy and published values, the ambiguity metric against RTKLIB's lambda
and Teunissen's closed-form success-rate bounds, grid parsing, and the bad-input battery of ``simkit campaign``."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import stats as sps

import simkit
from cli_errors import assert_clean_error
from simkit.ambiguity import adop_upper_bound
from simkit.gnss.differencing import float_solution
from simkit.campaign import CampaignInputError, mean_interval, parse_grid, plan, wilson_interval
from simkit.campaign.ambiguity_metric import ambiguity, dd_observations
from simkit.campaign.plan import grid_points, split_values


def test_wilson_interval_equals_scipy_binomtest():
    for n in (1, 7, 30, 263, 1000):
        for k in sorted({0, 1, n // 3, n - 1, n}):
            for conf in (0.9, 0.95, 0.99):
                ref = sps.binomtest(k, n).proportion_ci(confidence_level=conf, method="wilson")
                lo, hi = wilson_interval(k, n, conf)
                assert lo == pytest.approx(ref.low, abs=1e-12) and hi == pytest.approx(ref.high, abs=1e-12)
    lo, hi = wilson_interval(np.array([0, 5]), np.array([0, 10]))
    assert np.isnan(lo[0]) and np.isnan(hi[0]) and 0 < lo[1] < 0.5 < hi[1] < 1


def test_wilson_interval_reproduces_newcombe_1998_table():
    """Newcombe, Statistics in Medicine 17 (1998) 857-872, Table I, method 3 (Wilson score, no continuity
    correction), 95 %: printed to 4 decimals."""
    for k, n, lo, hi in ((81, 263, 0.2553, 0.3662), (15, 148, 0.0624, 0.1605), (0, 20, 0.0, 0.1611),
                         (1, 29, 0.0061, 0.1718)):
        got = wilson_interval(k, n, 0.95)
        assert got == pytest.approx((lo, hi), abs=5e-5)


def test_mean_interval_equals_scipy_t_interval():
    x = np.random.default_rng(3).normal(2.0, 0.5, 17)
    ref = sps.t.interval(0.95, x.size - 1, loc=x.mean(), scale=sps.sem(x))
    got = mean_interval(np.append(x, np.nan), 0.95)
    assert got["n"] == 17 and got["ci"] == pytest.approx(ref, rel=1e-12)
    assert mean_interval([1.0])["ci"] is None and mean_interval([])["n"] == 0


def test_grid_values_split_at_top_level_commas_and_multiply():
    assert split_values('[1, 2],"a,b", 3') == ["[1, 2]", '"a,b"', "3"]
    grid = parse_grid(["gnss.elevation_mask_deg=10,20,30", 'imu.preset="ideal","adis16488"'])
    points = grid_points(grid)
    assert len(points) == 6 and points[1] == ("gnss.elevation_mask_deg=10", 'imu.preset="adis16488"')
    specs = plan("quickstart", 3, ["gnss.elevation_mask_deg=10,20"], first_seed=5)
    assert [s.seed for s in specs] == [5, 6, 7, 5, 6, 7] and len({s.run_id for s in specs}) == 6
    with pytest.raises(CampaignInputError, match="--grid: gnss.elevation_mask_deg given twice"):
        parse_grid(["gnss.elevation_mask_deg=1", "gnss.elevation_mask_deg=2"])


def _rtklib_fix(a, Q):
    import pyrtklib

    n = a.size
    A = pyrtklib.Arr1Ddouble
    ab, Qb, F, s = A(n), A(n * n), A(n * 2), A(2)
    for i, v in enumerate(a.tolist()):
        ab[i] = v
    for i, v in enumerate(Q.T.ravel().tolist()):
        Qb[i] = v
    assert getattr(pyrtklib, "lambda")(n, 2, ab, Qb, F, s) == 0
    return np.rint([F[i] for i in range(n)]).astype(np.int64)


def test_ambiguity_metric_agrees_with_rtklib_and_lies_within_the_closed_form_bounds(tmp_path):
    """Static 3.965 m BDS B1I baseline, white constant-sigma noise only (so the float model is exact): the
    single-epoch ILS success count equals RTKLIB's lambda on the same float solutions, and the success rate's
    99.9 % Wilson interval meets [mean bootstrapped rate (lower bound, Teunissen 1999), mean ADOP upper bound]."""
    over = ["scenario.duration_s=300", "trajectory.segment[0].duration_s=300", "imu.preset=\"ideal\"",
            "gnss.errors.multipath=false", "gnss.errors.ionosphere=false", "gnss.errors.troposphere=false",
            "gnss.noise.model=\"constant\"", "gnss.noise.carrier_sigma_m=0.003", "gnss.noise.code_sigma_m=0.6"]
    path = simkit.run("xian_static_bds", out=tmp_path / "x.h5", seed=11, overrides=over)
    with simkit.open(path) as ds:
        m = ambiguity(ds)
        dd = dd_observations(ds, "B1I")
        lam = float(ds["gnss/wavelength_m"][0])
    assert m["ils_trials"] == 301 and m["epochs_skipped"] == 0
    ok = dd["ok"]
    rtk_success, upper = 0, []
    for t in range(ok.shape[0]):
        cols = np.flatnonzero(ok[t])
        fs = float_solution(dd["G"][t:t + 1, cols], dd["carrier"][t:t + 1, None, cols],
                            dd["code"][t:t + 1, None, cols], lam, 0.003, 0.6)
        rtk_success += bool(np.all(_rtklib_fix(fs.a_hat[0], fs.Qa[0]) == np.rint(dd["ambiguity"][t, cols])))
        upper.append(adop_upper_bound(fs.Qa[0]))
    assert m["ils_successes"] == rtk_success
    lo, hi = wilson_interval(m["ils_successes"], m["ils_trials"], 0.999)
    assert 0.5 < m["bootstrap_sr_mean"] < 0.99 and lo <= np.mean(upper) and hi >= m["bootstrap_sr_mean"]


def test_campaign_bad_input_is_one_clean_line(tmp_path, monkeypatch):
    import simkit.campaign.runner as runner

    (tmp_path / "afile").write_text("x")
    base = ["campaign", "quickstart", "-o", "out"]
    assert_clean_error(base + ["--runs", "0"], tmp_path, expect="--runs: expected a positive integer, got 0")
    assert_clean_error(base + ["--runs", "2", "--grid", "nokey"], tmp_path, expect="--grid: expected dotted.key")
    assert_clean_error(base + ["--runs", "2", "--grid", "imu.bogus=1,2"], tmp_path, expect="imu.bogus: unknown key")
    assert_clean_error(base + ["--runs", "2", "--metric", "nees"], tmp_path, expect="unknown metric 'nees'")
    assert_clean_error(base + ["--runs", "2", "--workers", "0"], tmp_path, expect="--workers: expected a positive")
    assert_clean_error(["campaign", "quickstart", "--runs", "2", "-o", "afile"], tmp_path,
                       expect="afile: exists and is not a folder")
    assert_clean_error(["campaign", "nosuch.toml", "--runs", "2", "-o", "out"], tmp_path, expect="SCENARIO")
    assert_clean_error(base, tmp_path, expect="--runs")
    monkeypatch.setattr(runner, "CONNECT_TIMEOUT_S", 0.5)
    assert_clean_error(base + ["--runs", "1", "--scheduler", "tcp://127.0.0.1:9"], tmp_path,
                       expect="--scheduler: tcp://127.0.0.1:9: cannot connect")


def test_task_adds_missing_metrics_without_rerunning_and_keeps_a_completed_run(tmp_path):
    from simkit.campaign.plan import expected_text
    from simkit.campaign.runner import triage
    from simkit.campaign.task import execute

    over = ("scenario.duration_s=5", "trajectory.segment[0].duration_s=5")
    spec = plan("xian_static_bds", 1, overrides=over)[0]
    first = execute(spec, str(tmp_path), ("imu_errors",))
    h5 = tmp_path / f"{spec.run_id}.h5"
    stamp = h5.stat().st_mtime_ns
    done, todo = triage([spec], tmp_path, ("imu_errors",))
    assert list(done) == [spec.run_id] and not todo
    done, todo = triage([spec], tmp_path, ("imu_errors", "gnss_errors"))
    assert not done and todo[0][1]["sha256"] == first["sha256"]
    second = execute(spec, str(tmp_path), ("imu_errors", "gnss_errors"), todo[0][1])
    assert set(second["metrics"]) == {"imu_errors", "gnss_errors"} and second["sha256"] == first["sha256"]
    again = execute(spec, str(tmp_path), ("imu_errors", "gnss_errors"), None, expected_text(spec))
    assert again == second and h5.stat().st_mtime_ns == stamp  # a re-executed task leaves a finished run alone
    with simkit.open(h5) as ds:  # another seed behind the same name is not "complete"
        assert ds.attrs["seed"] == spec.seed
    assert triage([spec.__class__(spec.run_id, spec.scenario, 7, spec.overrides, 0)], tmp_path,
                  ("imu_errors",))[1][0][1] is None


def test_a_folder_of_other_settings_is_refused_and_left_as_it_was(tmp_path):
    """Regression: reusing a campaign folder with other settings overwrote its runs silently."""
    from cli_errors import digest
    from simkit.campaign.task import execute

    over = ["scenario.duration_s=5", "trajectory.segment[0].duration_s=5"]
    spec = plan("xian_static_bds", 1, overrides=over)[0]
    (tmp_path / "c" / "runs").mkdir(parents=True)
    execute(spec, str(tmp_path / "c" / "runs"), ("imu_errors",))
    h5 = tmp_path / "c" / "runs" / f"{spec.run_id}.h5"
    before = digest(h5)
    args = ["campaign", "xian_static_bds", "--runs", "1", "-o", "c", "--metric", "imu_errors", "-q"]
    longer = ["--set", "scenario.duration_s=6", "--set", "trajectory.segment[0].duration_s=6"]
    assert_clean_error(args + longer, tmp_path, expect="c: holds a campaign with other settings (run p000_s000000")
    assert_clean_error(args + sum((["--set", o] for o in over), []) + ["--first-seed", "0", "--grid",
                       "imu.preset=\"ideal\""], tmp_path, expect="holds a campaign with other settings")
    assert digest(h5) == before


def test_index_file_holds_the_run_table_and_virtual_datasets_over_the_runs(tmp_path):
    import h5py

    import simkit
    from simkit.campaign.index import write_index

    (tmp_path / "runs").mkdir()
    rows = []
    for seed in (3, 4):
        simkit.run("quickstart", out=tmp_path / "runs" / f"s{seed}.h5", seed=seed,
                   overrides=["scenario.duration_s=2"])
        rows.append({"run_id": f"s{seed}", "status": "ok", "file": f"runs/s{seed}.h5", "sha256": "x", "seed": seed,
                     "point": 0, "elapsed_s": 1.0, "metrics": {"gnss_errors.rms": 0.1 * seed}})
    rows.append({"run_id": "s5", "status": "failed", "file": "runs/s5.h5", "sha256": None, "seed": 5, "point": 0,
                 "elapsed_s": None, "metrics": {}})
    stacked = write_index(tmp_path, rows)
    assert "imu/gyro" in stacked and "gnss/obs/L1C/carrier" in stacked
    moved = tmp_path.parent / (tmp_path.name + "_moved")
    tmp_path.rename(moved)   # relative sources: the folder can move
    with h5py.File(moved / "index.h5", "r") as f:
        assert [s.decode() for s in f["campaign/runs/status"][:]] == ["ok", "ok", "failed"]
        np.testing.assert_allclose(f["campaign/runs/gnss_errors.rms"][:2], [0.3, 0.4])
        assert np.isnan(f["campaign/runs/gnss_errors.rms"][2])
        gyro = f["campaign/virtual/imu.gyro"][...]
        with h5py.File(moved / "runs" / "s4.h5", "r") as run:
            np.testing.assert_array_equal(gyro[1], run["imu/gyro"][...])


def test_index_from_the_workers_recorded_layouts_equals_the_index_from_walking_the_files(tmp_path):
    """The client stacks the runs from the layouts the workers recorded; the result must be the index that walking
    the files gives (same stacked paths, shapes, dtypes and values), and a layout that disagrees between runs
    leaves that path unstacked, as a file that disagrees does."""
    import h5py

    import simkit
    from simkit.campaign.index import write_index
    from simkit.campaign.task import dataset_layout
    from simkit.io import open_dataset

    rows, records = [], {}
    for seed in (3, 4):
        (tmp_path / "runs").mkdir(exist_ok=True)
        simkit.run("quickstart", out=tmp_path / "runs" / f"s{seed}.h5", seed=seed, overrides=["scenario.duration_s=2"])
        rows.append({"run_id": f"s{seed}", "status": "ok", "file": f"runs/s{seed}.h5", "sha256": "x", "seed": seed,
                     "point": 0, "elapsed_s": 1.0, "metrics": {}})
        with open_dataset(tmp_path / "runs" / f"s{seed}.h5") as ds:
            records[f"s{seed}"] = {"datasets": dataset_layout(ds)}
    walked = write_index(tmp_path, rows)
    with h5py.File(tmp_path / "index.h5", "r") as f:
        expect = {k: (v.shape, v.dtype, v[...]) for k, v in f["campaign/virtual"].items()}
    assert write_index(tmp_path, rows, records) == walked
    with h5py.File(tmp_path / "index.h5", "r") as f:
        got = f["campaign/virtual"]
        assert sorted(got) == sorted(expect)
        for k, (shape, dtype, values) in expect.items():
            assert got[k].shape == shape and got[k].dtype == dtype
            np.testing.assert_array_equal(got[k][...], values)
    records["s4"]["datasets"]["imu/gyro"][0][0] += 1   # a run of another length: not stackable
    assert "imu/gyro" not in write_index(tmp_path, rows, records) and "imu/accel" in walked
    del records["s4"]["datasets"]                      # a record of an older simkit: the files are walked
    assert write_index(tmp_path, rows, records) == walked


FAULT_PROBE = r"""
import resource, sys
import numpy as np
from simkit.campaign.task import tune_worker_process

def faults_per_block():
    x = np.ones(1 << 17)  # 1 MiB: above the 128 KiB mmap threshold Dask's setting freezes
    del x
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(50):
        x = np.ones(1 << 17)
        del x
    return (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before) / 50

untuned = faults_per_block()
assert tune_worker_process()
print(untuned, faults_per_block())
"""


@pytest.mark.skipif(not __import__("platform").libc_ver()[0] == "glibc", reason="glibc's mallopt only")
def test_worker_tuning_undoes_the_page_faults_of_dasks_malloc_setting():
    """Under Dask's MALLOC_TRIM_THRESHOLD_=65536 every 1 MiB temporary is a fresh mmap that page-faults all of its
    256 pages in; after tune_worker_process() the freed block is reused without faults."""
    import os
    import subprocess
    import sys

    env = dict(os.environ, MALLOC_TRIM_THRESHOLD_="65536")
    out = subprocess.run([sys.executable, "-c", FAULT_PROBE], env=env, capture_output=True, text=True, check=True)
    untuned, tuned = map(float, out.stdout.split())
    assert untuned > 200
    assert tuned < 20


def test_the_mean_interval_of_identical_values_is_the_value_itself():
    """Regression: scipy's Student-t interval is NaN for a zero scale, and the campaign summary (JSON without NaN)
    failed on a metric that every run gave the same value."""
    from simkit.campaign.stats import mean_interval

    assert mean_interval([2.5, 2.5, 2.5])["ci"] == [2.5, 2.5]
