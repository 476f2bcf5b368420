"""Plugin interface: run a user's navigation filter over a simkit file, time it and score it.

A filter is any object with

- ``predict(imu: ImuSample) -> None``: one IMU sample (called for every sample, in time order);
- ``update(gnss: GnssEpoch) -> None``: one GNSS epoch (called after every IMU sample up to its time);
- ``solution() -> simkit.solution.Solution``: its estimates in simkit conventions (ENU, body right-forward-up,
  scalar-last quaternions; :func:`simkit.referee.solution_from_ned` converts NED / forward-right-down outputs),
  with ``cov``/``state_names`` for the NEES test and ``nis``/``nis_dof`` extras for the NIS test;
- optionally ``start(initial: TrueInitialState)``: the true state at the first IMU sample, plus ``lever_arm_b``,
  for filters that are initialised externally (a referee run compares filters, not alignment procedures).

:func:`run_filter` feeds the file to the filter, times ``predict``, ``update`` and ``solution`` separately, and scores
the solution against the truth (:func:`simkit.referee.score`). The interface is deliberately per sample: a
filter that works in batches (pyins' ``run_feedback_filter``) buffers in ``predict``/``update`` and filters in
``solution``; its time then shows there.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..io import has, open_dataset, read_gnss, read_imu, truth_at
from .errors import RefereeInputError
from .score import Score, score
from .spec import Spec
from .truth import read_truth


@dataclass(frozen=True)
class ImuSample:
    """One IMU sample: ``t`` s since the scenario start, ``dt`` s since the previous sample (the nominal
    interval for the first); ``gyro`` (3,) rad/s and ``accel`` (3,) m/s^2 measured in the body frame
    (x right, y forward, z up), rates (not increments)."""

    t: float
    dt: float
    gyro: np.ndarray
    accel: np.ndarray


@dataclass(frozen=True)
class GnssEpoch:
    """One receiver epoch ``t`` (s since the scenario start), the file's ``/gnss`` at that epoch: ``sat_id``
    (S,) names; ``sat_pos_ecef`` (S, 3) m at emission time in the ECEF frame of the emission epoch (add the
    Sagnac term); ``sat_clock`` (S,) s; ``lever_arm_b`` (A, 3) m; per signal name ``code`` (A, S) m, ``carrier``
    (A, S) cycles, ``doppler`` (A, S) Hz, ``cn0`` (A, S) dB-Hz, ``lli`` (A, S); ``wavelength_m`` per signal.
    NaN where a satellite is not tracked."""

    t: float
    sat_id: tuple
    sat_pos_ecef: np.ndarray
    sat_clock: np.ndarray
    lever_arm_b: np.ndarray
    code: dict
    carrier: dict
    doppler: dict
    cn0: dict
    lli: dict
    wavelength_m: dict = field(default_factory=dict)
    gps_week: int = 0
    gps_sow: float = 0.0


@dataclass(frozen=True)
class TrueInitialState:
    """The true state at ``t``: ``pos_ecef`` (3,) m, ``vel_enu`` (3,) m/s, ``quat_nb`` (4,) body->ENU
    scalar-last, ``lever_arm_b`` (A, 3) m; ``start_gps_week``/``start_gps_sow`` the scenario start."""

    t: float
    pos_ecef: np.ndarray
    vel_enu: np.ndarray
    quat_nb: np.ndarray
    lever_arm_b: np.ndarray
    start_gps_week: int
    start_gps_sow: float


@dataclass(frozen=True)
class RunResult:
    """``score`` of the filter's solution; ``timing`` {predict_s, update_s, solution_s, total_s,
    imu_samples, gnss_epochs, imu_samples_per_s}; ``solution`` itself."""

    solution: object
    score: Score
    timing: dict


OBS_KINDS = ("code", "carrier", "doppler", "cn0", "lli")
BLOCK_EPOCHS = 600   # GNSS epochs (and the IMU samples between them) read at a time: bounded memory


def _gnss_block(ds, m0: int, m1: int) -> dict:
    """GNSS epochs m0..m1 of the file as arrays (per signal and kind for the observations)."""
    g = read_gnss(ds, epochs=slice(m0, m1), obs=OBS_KINDS)
    return {"t": g.t, "sat_id": tuple(str(s) for s in g.sat_id), "sat_pos_ecef": g.sat_pos_ecef,
            "sat_clock": g.sat_clock, "lever_arm_b": g.lever_arm_b,
            "wavelength_m": dict(zip(g.signals, g.wavelength_m.tolist())), **g.obs}


def _epoch(g: dict, m: int, week: int, sow: float) -> GnssEpoch:
    per = {kind: {s: x[m] for s, x in g[kind].items()} for kind in OBS_KINDS}
    t = float(g["t"][m])
    return GnssEpoch(t, g["sat_id"], g["sat_pos_ecef"][m], g["sat_clock"][m], g["lever_arm_b"], **per,
                     wavelength_m=g["wavelength_m"], gps_week=week + int((sow + t) // 604800),
                     gps_sow=float((sow + t) % 604800))


def _check_file(ds, path):
    if not has(ds, "imu", "gyro") or not has(ds, "gnss", "t"):
        raise RefereeInputError(path, "the plugin runner needs /imu and /gnss (a scenario with [imu] and [gnss])")


def _check_filter(flt):
    missing = [m for m in ("predict", "update", "solution") if not callable(getattr(flt, m, None))]
    if missing:
        raise RefereeInputError("filter", f"{type(flt).__name__} has no {', '.join(missing)} method "
                                          f"(expected predict(imu), update(gnss), solution())")


def _start(flt, ds, truth, t0: float, start):
    if callable(getattr(flt, "start", None)):
        at = truth_at(truth, np.clip(t0, truth.t[0], truth.t[-1]))
        flt.start(TrueInitialState(float(at.t[0]), at.pos_ecef[0], at.vel_enu[0], at.quat_nb[0],
                                   truth.lever_arm_b, *start))


def _feed(flt, ds, t_imu, n: int, start, clock: dict, bar) -> int:
    """Give the filter every IMU sample (0..n) and every GNSS epoch up to t_imu[n - 1], block by block (the IMU
    samples of a block of GNSS epochs are read at once); returns the number of GNSS epochs."""
    nominal = t_imu[1] - t_imu[0] if n > 1 else 0.0
    dt = np.diff(t_imu[:n], prepend=t_imu[0] - nominal)
    t_gnss = read_gnss(ds, satellites=False).t
    n_epochs = int(np.searchsorted(t_gnss, t_imu[n - 1], side="right"))
    after = np.searchsorted(t_imu[:n], t_gnss[:n_epochs], side="right")   # IMU samples before each epoch
    k0 = 0
    for m0 in range(0, n_epochs + 1, BLOCK_EPOCHS):
        m1 = min(m0 + BLOCK_EPOCHS, n_epochs)
        g = _gnss_block(ds, m0, m1)
        ends = [*after[m0:m1], *([n] if m1 == n_epochs else [])]
        base, top = k0, (ends[-1] if ends else k0)
        imu = read_imu(ds, fields=("gyro", "accel"), epochs=slice(base, top))
        for j, k1 in enumerate(ends):
            c0 = time.perf_counter()
            for k in range(k0, k1):
                flt.predict(ImuSample(float(t_imu[k]), float(dt[k]), imu.gyro[k - base], imu.accel[k - base]))
            c1 = time.perf_counter()
            if j < m1 - m0:
                flt.update(_epoch(g, j, *start))
            clock["predict_s"] += c1 - c0
            clock["update_s"] += time.perf_counter() - c1
            bar.update(k1 - k0)
            k0 = k1
        if m1 == n_epochs:
            break
    return n_epochs


def run_filter(flt, path, spec: Spec | None = None, duration_s: float | None = None,
               progress: bool = False) -> RunResult:
    """Run filter ``flt`` over the simkit file ``path`` (the first ``duration_s`` seconds, or all), time it and
    score its solution against the truth with ``spec``. The file is read in blocks of :data:`BLOCK_EPOCHS`."""
    _check_filter(flt)
    with open_dataset(path) as ds:
        _check_file(ds, path)
        t_imu = read_imu(ds, fields=()).t
        n = len(t_imu) if duration_s is None else int(np.searchsorted(t_imu, t_imu[0] + duration_s, side="right"))
        start = (int(ds.attrs["start_gps_week"]), float(ds.attrs["start_gps_sow"]))
        truth = read_truth(path, t_imu[0], t_imu[n - 1])
        _start(flt, ds, truth, t_imu[0], start)
        clock = {"predict_s": 0.0, "update_s": 0.0}
        with _bar(progress, n) as bar:
            epochs = _feed(flt, ds, t_imu, n, start, clock, bar)
    c0 = time.perf_counter()
    sol = flt.solution()
    clock["solution_s"] = time.perf_counter() - c0
    total = sum(clock.values())
    timing = {**clock, "total_s": total, "imu_samples": int(n), "gnss_epochs": epochs,
              "imu_samples_per_s": n / total if total > 0 else float("inf")}
    return RunResult(sol, score(truth, sol, spec, where=type(flt).__name__), timing)


def _bar(progress: bool, total: int):
    from tqdm import tqdm

    return tqdm(total=total, desc="referee", unit="sample", disable=not progress, leave=False)
