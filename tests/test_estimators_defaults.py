"""The estimators' defaults work on every bundled scenario, read no truth, and give
filters whose covariance matches their errors (NEES and NIS against the chi-square bounds of their dof).

Each scenario is simulated once (shortened where the full length adds nothing but time) and every filter runs
with no ``--set`` key; the errors come from the file's truth through the referee."""
import numpy as np
import pytest
from cli_errors import run_cli
from scipy.stats import chi2

import simkit
from simkit.estimators import SOLVERS
from simkit.io import read_solution
from simkit.referee.score import score
from simkit.referee.spec import parse_spec
from simkit.referee.truth import read_truth

# full length except the 24 h static site (its first 300 s: the attitude alignment and the filter's convergence),
# with the scenarios' realistic truth-side errors (broadcast orbits and clocks, ionosphere and troposphere
# residuals: docs/truth_errors.md), which the Kalman filters' GNSS-error states model
NO_TRUTH_ERRORS = "gnss.truth_errors.model='none'"
SCENARIOS = {"quickstart": [], "high_dynamic": [], "airborne_stim300": ["scenario.duration_s=300"],
             "xian_static_bds": ["scenario.duration_s=300"]}
FILTERS = ("kf15", "hinf", "kf21", "kf15_dd")


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("defaults")
    return {name: simkit.run(name, out=d / f"{name}.h5", overrides=over) for name, over in SCENARIOS.items()}


@pytest.fixture(scope="module")
def solved(files):
    """{(scenario, filter): (Solution, Score)} with every default (kf15_dd where the file has 2+ antennas: it
    needs a baseline)."""
    out = {}
    for name, path in files.items():
        truth = read_truth(path)
        with simkit.open(path) as ds:
            for f in FILTERS if ds["gnss/antennas/lever_arm_b"].shape[0] > 1 else FILTERS[:3]:
                sol = SOLVERS[f](ds, {}, False)
                out[name, f] = sol, score(truth, sol)
    return out


def _after(sc, seconds):
    return sc.errors.t >= sc.errors.t[0] + seconds


def test_solve_with_no_options_works_on_every_bundled_scenario(files, tmp_path):
    """Item 2: the default filters (spp, kf15) of ``simkit solve FILE``, on the static site too."""
    for name, path in files.items():
        proc = run_cli(["solve", str(path), "-q"], tmp_path)
        assert proc.returncode == 0, (name, proc.stderr)
        assert read_solution(path, "kf15").t.size > 0


def test_every_filter_defaults_to_auto_alignment_and_reads_no_truth(solved, capsys):
    for (name, f), (sol, _) in solved.items():
        assert sol.config["params"]["align"] == "auto", (name, f)
        assert sol.config["align_used"] in ("static", "motion", "attitude"), (name, f)
        assert sol.config["truth_inputs"] == [], (name, f)
        assert sol.config["params"]["gnss"] == "spp", (name, f)
    assert "truth" not in capsys.readouterr().err
    # the static site with 3 antennas aligns from the carrier-phase attitude, which "motion" could not
    assert solved["xian_static_bds", "kf15"][0].config["align_used"] == "attitude"


def test_kf21_with_one_baseline_uses_no_attitude_by_default(solved):
    """Item 11: quickstart has 2 antennas; "auto" was the truth + 0.3 deg, now no attitude updates."""
    sol = solved["quickstart", "kf21"][0]
    assert sol.config["attitude_source"] == "none" and "attitude_nis_mean" not in sol.config
    assert solved["airborne_stim300", "kf21"][0].config["attitude_source"] == "attitude"  # 3 antennas


@pytest.mark.parametrize("key, value", [("attitude_source", "truth"), ("gnss", "truth"), ("align", "truth")])
def test_a_truth_input_is_explicit_warned_and_recorded(files, capsys, key, value):
    with simkit.open(files["quickstart"]) as ds:
        sol = SOLVERS["kf21"](ds, {key: value}, False)
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("warning: kf21 reads /truth") and f"estimator.{key}=truth" in err[0]
    assert sol.config["truth_inputs"] == [key]


def test_hinf_stays_near_kf15_on_spp_fixes_on_every_scenario(solved):
    """Item 10: Wu's gamma rule with a margin of 1e-4 made height spikes of 2.9 km on high_dynamic. On the same
    SPP fixes the H-infinity filter's position error stays within 3x the Kalman filter's on every axis, and its
    largest error within a few SPP sigmas (1 m code sigma: metres, not kilometres)."""
    for name in SCENARIOS:
        kf, hf = solved[name, "kf15"][1], solved[name, "hinf"][1]
        late = _after(kf, 30.0)
        rms = [np.sqrt(np.mean(s.errors.pos_enu[_after(s, 30.0)] ** 2, axis=0)) for s in (kf, hf)]
        assert np.all(rms[1] <= 3.0 * rms[0]), (name, rms)
        assert np.abs(hf.errors.pos_enu[late]).max() < 5.0, name


def _nees_inside(sc, seconds):
    """Fraction of epochs after ``seconds`` whose NEES (pos/vel/att, 9 dof) is inside its 95 % bounds."""
    late, dof = _after(sc, seconds), len(sc.nees["states"])
    v = sc.nees["series"][late]
    return np.mean((v >= chi2.ppf(0.025, dof)) & (v <= chi2.ppf(0.975, dof)))


@pytest.mark.parametrize("name, f", [("quickstart", "kf15"), ("quickstart", "kf21"), ("quickstart", "kf15_dd"),
                                     ("airborne_stim300", "kf15"), ("airborne_stim300", "kf21"),
                                     ("airborne_stim300", "kf15_dd"), ("xian_static_bds", "kf21")])
def test_default_covariance_is_consistent_with_the_errors(solved, name, f):
    """Item 8: kf15 on quickstart had 3.8 % of its epochs inside the NEES bounds (covariance far too large: the
    SPP fixes were weighted as 3 m code and 0.1 m/s Doppler, against the simulated 0.65-1.4 m and 0.04 m/s).
    Then, with the realistic truth-side errors, 0 %: the filters took the fixes' metre-level error, correlated
    over minutes, as white noise and averaged it down (NEES mean 225 on quickstart, 428 on airborne_stim300).
    With the GNSS-error states after 30 s of convergence most epochs are inside. (high_dynamic, the kf15 heading
    on the static site and H-infinity, whose P bounds rather than estimates the error, are the documented
    exceptions: docs/estimators.md.)"""
    sc = solved[name, f][1]
    assert _nees_inside(sc, 30.0) >= 0.75, (name, f, _nees_inside(sc, 30.0))


def test_without_the_gnss_error_states_the_same_filter_is_overconfident(files):
    """The other side of the test above: the same fixes taken as white noise (``gnss_error_sigma_m = 0``)."""
    truth = read_truth(files["quickstart"])
    with simkit.open(files["quickstart"]) as ds:
        sc = score(truth, SOLVERS["kf15"](ds, {"gnss_error_sigma_m": [0.0, 0.0, 0.0]}, False))
    assert _nees_inside(sc, 30.0) < 0.25 and np.nanmean(sc.nees["series"]) > 5 * len(sc.nees["states"])


def test_filters_store_their_nis_for_the_referee(solved, files):
    """Item 8: the referee's NIS test needs ``nis`` and ``nis_dof``; a spec's NIS check gave "value -"."""
    sol, sc = solved["airborne_stim300", "kf15"]
    assert set(np.unique(sol.extras["nis_dof"])) <= {0, 6}
    assert sc.nis is not None and sc.nis["epochs"] == sol.t.size
    lo, hi = chi2.ppf([0.025, 0.975], 6)
    nis = sol.extras["nis"]
    assert np.mean((nis >= lo) & (nis <= hi)) >= 0.75
    # the spec check now has a value (it was None, "value -", whatever the filter did)
    spec = parse_spec({"consistency": {"nis_min_fraction_inside": 0.75}})
    check = [c for c in score(read_truth(files["airborne_stim300"]), sol, spec).checks if c["name"].startswith("NIS")]
    assert len(check) == 1 and check[0]["value"] is not None and check[0]["passed"]


def test_tdcp_lever_attitude_reads_the_truth_only_when_asked(files, capsys):
    """``auto`` with one baseline is "none" (never the truth); "truth" is warned about and recorded."""
    from simkit.attitude import SOLVERS as ATTITUDE

    with simkit.open(files["quickstart"]) as ds:
        auto = ATTITUDE["tdcp"](ds, {}, False)
        assert auto.config["lever_attitude_used"] == "none" and auto.config["truth_inputs"] == []
        assert capsys.readouterr().err == ""
        study = ATTITUDE["tdcp"](ds, {"lever_attitude": "truth"}, False)
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "warning: tdcp reads /truth: estimator.lever_attitude=truth" in err[0]
    assert study.config["truth_inputs"] == ["lever_attitude"]


@pytest.fixture(scope="module")
def static_3h(tmp_path_factory):
    return simkit.run("xian_static_bds", out=tmp_path_factory.mktemp("static") / "xian3h.h5",
                      overrides=["scenario.duration_s=10800", NO_TRUTH_ERRORS])


def test_bias_instability_keeps_a_long_static_run_consistent(static_3h):
    """Item 8: the MEMS IMU's bias instability (a flicker bias, IEEE B) had no process noise in the filter, whose
    bias estimate then grew more confident every hour while the true bias kept wandering: kf21's height error
    was 2.8 m RMS over 3 h, twice its own input's (the SPP fixes, 1.3 m), and 23 % of its NEES inside. The filter
    now does better than its fixes and is consistent."""
    from simkit.estimators.registry import merged, spp_fixes
    from simkit.frames import ecef_to_enu_vec, ecef_to_lla

    truth = read_truth(static_3h)
    with simkit.open(static_3h) as ds:  # white fixes (no truth-side errors): no GNSS-error states
        sol = SOLVERS["kf21"](ds, {"gnss_error_sigma_m": [0.0, 0.0, 0.0]}, False)
        fx = spp_fixes(ds, merged("spp", {}))
        antenna = ds["gnss/truth/antenna_pos_ecef"][:, 0]
    lla = ecef_to_lla(antenna)
    spp_up = ecef_to_enu_vec(fx.pos_ecef - antenna, lla[:, 0], lla[:, 1])[:, 2]
    sc = score(truth, sol)
    late = _after(sc, 30.0)
    up_rms = np.sqrt(np.mean(sc.errors.pos_enu[late, 2] ** 2))
    assert up_rms < 0.75 * np.sqrt(np.nanmean(spp_up**2)), up_rms
    assert _nees_inside(sc, 30.0) >= 0.8
