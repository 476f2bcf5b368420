"""The ``simkit solve`` registry: file in, :class:`simkit.solution.Solution` out (the pieces do the work)."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ..frames import euler_from_attitude
from ..gnss.differencing import dd_matrix
from ..solution import Solution
from . import wahba
from .dd import FloatGroup, float_solution, run_breaks
from .errors import AttitudeInputError
from .params import AMBIGUITY_DEFAULTS, merge
from .reading import FileData, read
from .resolve import FixPolicy, Resolution, resolve, resolve_held

STATUS = {"none": -1, "float": 0, "fixed": 1, "partial": 2, "wrong fix": 3}
_METHOD = {"attitude": "lambda", "attitude_c": "clambda", "attitude_mc": "mclambda"}
SOLVER_NAMES = tuple(_METHOD)


def _progress(items, progress, desc):
    """``items`` with a progress bar that says when a kernel runs interpreted while numba compiles it."""
    if not progress:
        yield from items
        return
    from tqdm import tqdm

    from ..ambiguity.warmup import compiling

    with tqdm(items, desc=desc, unit="group") as bar:
        shown = ""
        for item in bar:
            names = compiling()
            note = f"{', '.join(names)}: interpreted while numba compiles it" if names else ""
            if note != shown:
                bar.set_postfix_str(note)
                shown = note
            yield item


def body_baselines(lever_arm: np.ndarray) -> np.ndarray:
    """F (3, r): antenna k minus antenna 0 in the body frame (m)."""
    return (lever_arm[1:] - lever_arm[0]).T


def _wrong(grp: FloatGroup, res: Resolution, fd: FileData) -> np.ndarray:
    """True where an accepted (full or partial) fix differs from the file's true DD ambiguities."""
    g, _, a, s = fd.ambiguity.shape
    D = dd_matrix(grp.signal, grp.sat, grp.ref, a, s, g)
    truth = fd.ambiguity[:, grp.epochs].transpose(1, 0, 2, 3).reshape(len(grp.epochs), -1) @ D.T
    out = np.zeros(len(grp.epochs), bool)
    for i, (zc, Z) in enumerate(zip(res.z_check, res.Z)):
        out[i] = zc.size > 0 and np.any(Z.T @ truth[i] != zc)
    return out, truth


def continuity_breaks(grp: FloatGroup, lli: np.ndarray) -> np.ndarray:
    """(K,) bool: the group's epochs where ambiguity continuity breaks: the first, after a gap in the epochs, or
    with a loss-of-lock flag (``lli`` (G, M, A, S) > 0) on any antenna for a satellite or reference used."""
    return run_breaks(grp, lli)


def _attitude(res: Resolution, F: np.ndarray, method: str, kind: str):
    """(R (K, 3, 3), cov (K, X, X), names) from the fixed baselines."""
    K, r = len(res.b), F.shape[1]
    b = res.b.reshape(K, r, 3).transpose(0, 2, 1)
    if kind == "baseline" or r == 1:
        pitch, heading, cov = wahba.single_baseline(b[:, :, 0], res.Qb[:, :3, :3], F[:, 0])
        R = Rotation.from_euler("ZX", np.stack([-heading, pitch], -1)).as_matrix()
        return R, cov, ("pitch", "heading")
    if method == "mclambda" and kind == "wls":
        R = np.where(np.isfinite(res.rotation), res.rotation, wahba.wahba_wls(b, F, res.Qb))
        P = wahba.phi_covariance(R, F, res.Qb)
    elif kind == "wls":
        R = wahba.wahba_wls(b, F, res.Qb)
        P = wahba.phi_covariance(R, F, res.Qb)
    else:
        w = 1.0 / np.stack([np.trace(res.Qb[:, 3 * j:3 * j + 3, 3 * j:3 * j + 3], axis1=1, axis2=2)
                            for j in range(r)], -1)
        est = (lambda x: wahba.wahba_svd(x, F, w)) if kind == "svd" else (lambda x: wahba.badshah_eq10(x, F))
        R = est(b)
        P = wahba.propagated_covariance(est, b, res.Qb)
    cov = wahba.euler_covariance(R, P)
    return R, cov, ("pitch", "roll", "heading")


def _empty(M: int, r: int, g: int, s: int, names) -> dict:
    nan = np.nan
    x = len(names)
    return {"quat": np.full((M, 4), nan), "euler": np.full((M, 3), nan), "cov": np.full((M, x, x), nan),
            "status": np.full(M, -1, np.int8), "ratio": np.full(M, nan), "ratio_is_bound": np.zeros(M, bool),
            "success_rate": np.full(M, nan), "success_rate_bounds": np.full((M, 2), nan), "ffrt_mu": np.full(M, nan),
            "n_sats": np.zeros(M, np.int16), "dd_ambiguity": np.full((M, r, g, s), nan),
            "dd_ambiguity_true": np.full((M, r, g, s), nan), "reference_sat": np.full((M, g, s), -1, np.int16),
            "baseline_enu": np.full((M, r, 3), nan), "baseline_body": np.full((M, r, 3), nan),
            "baseline_float_enu": np.full((M, r, 3), nan), "atdop": np.full((M, 3), nan),
            "atdop_weighted": np.full((M, 3), nan),
            "sigma_dd_carrier": np.full(M, nan)}


def _store(out: dict, grp: FloatGroup, res: Resolution, fd: FileData, R, cov):
    """Write one group's results into the (M, ...) output arrays."""
    e, K = grp.epochs, len(grp.epochs)
    r, n = grp.a_hat.shape[1] // len(grp.sat), len(grp.sat)
    wrong, truth = _wrong(grp, res, fd)
    status = np.where(res.accepted, 1, np.where(res.partial, 2, 0))
    out["status"][e] = np.where(wrong, 3, status)
    out["ratio"][e], out["success_rate"][e] = res.ratio, res.success_rate
    out["ratio_is_bound"][e] = res.bounded
    out["success_rate_bounds"][e], out["ffrt_mu"][e] = res.sr_bounds, res.mu
    out["n_sats"][e] = len(np.unique(np.concatenate([grp.sat, grp.ref])))
    for k in range(r):
        rows = slice(k * n, (k + 1) * n)
        out["dd_ambiguity"][e[:, None], k, grp.signal, grp.sat] = res.z[:, rows]
        out["dd_ambiguity_true"][e[:, None], k, grp.signal, grp.sat] = truth[:, rows]
    out["reference_sat"][e[:, None], grp.signal, grp.sat] = grp.ref
    b = res.b.reshape(K, r, 3)
    out["baseline_enu"][e], out["baseline_float_enu"][e] = b, grp.b_hat.reshape(K, r, 3)
    out["baseline_body"][e] = np.einsum("kji,krj->kri", R, b)
    out["quat"][e] = Rotation.from_matrix(R).as_quat()
    out["euler"][e] = euler_from_attitude(Rotation.from_matrix(R))
    out["cov"][e] = cov
    out["sigma_dd_carrier"][e] = np.sqrt(np.mean(np.diagonal(grp.Qphi, axis1=1, axis2=2), axis=1))


def resolve_options(p: dict, partial: bool = True) -> FixPolicy:
    """The :class:`FixPolicy` of the merged ambiguity parameters ``p`` (validation, its threshold, pf and draws,
    the work cap; partial fixing unless ``partial`` is False)."""
    return FixPolicy(ratio_threshold=p["ratio_threshold"], partial_p0=(p["partial_p0"] or None) if partial else None,
                     max_nodes=int(p["max_nodes"]), validation=p["validation"], pf=p["pf"],
                     ffrt_samples=int(p["ffrt_samples"]))


def solve_arrays(fd: FileData, method: str, p: dict, progress: bool = False) -> tuple[dict, tuple]:
    """Float solution, ambiguity resolution and attitude of every epoch of ``fd``: (outputs (M, ...), names)."""
    F = body_baselines(fd.lever_arm)
    g, M, a, s = fd.obs.carrier.shape
    single = p["attitude"] == "baseline" or F.shape[1] == 1
    names = ("pitch", "heading") if single else ("pitch", "roll", "heading")
    out = _empty(M, a - 1, g, s, names)
    groups = float_solution(fd.obs, np.radians(p["mask_deg"]), p["max_sats"] or None, p["float_epochs"],
                            bool(p["static"]), fd.lli)
    for grp in _progress(groups, progress, f"attitude ({method})"):
        policy = resolve_options(p)
        if p["continuity"] and p["every"] == 1:
            res = resolve_held(grp, method, F, continuity_breaks(grp, fd.lli), policy)
        else:
            res = resolve(grp, method, F, policy)
        R, cov, _ = _attitude(res, F, method, p["attitude"])
        _store(out, grp, res, fd, R, cov)
        if not single:
            out["atdop"][grp.epochs] = wahba.euler_atdop(R, F, grp.G)
            out["atdop_weighted"][grp.epochs] = wahba.euler_atdop(R, F, grp.G, grp.Qphi)
    if single:
        out["euler"][:, 1] = np.nan
    return out, names


_UNITS = {"status": "-1 none, 0 float, 1 fixed, 2 partial, 3 wrong fix", "ratio": "1", "ratio_is_bound": "bool",
          "success_rate": "1", "success_rate_bounds": "1 (lower, upper)", "ffrt_mu": "1",
          "n_sats": "1", "dd_ambiguity": "cycles", "dd_ambiguity_true": "cycles",
          "reference_sat": "index into /gnss/sat_id", "baseline_enu": "m", "baseline_body": "m",
          "baseline_float_enu": "m", "atdop": "rad/m", "atdop_weighted": "rad/m (x sigma_dd_carrier: the weighted "
          "fit's sd)", "sigma_dd_carrier": "m"}


def solver(name: str):
    """The registry function of ``name`` (one of :data:`SOLVER_NAMES`)."""
    method = _METHOD[name]

    def solve(ds, params: dict | None = None, progress: bool = False) -> Solution:
        """Attitude from the file's multi-antenna carrier phase (see docs/attitude.md)."""
        p = merge(AMBIGUITY_DEFAULTS, params, name)  # checks the choices and limits of every key
        fd = read(ds, p)
        if method == "mclambda" and fd.lever_arm.shape[0] < 3:
            raise AttitudeInputError("gnss/antennas/lever_arm_b", "MC-LAMBDA needs at least 3 antennas")
        out, names = solve_arrays(fd, method, p, progress)
        single = len(names) == 2
        extras = {k: out[k] for k in _UNITS}
        config = {"estimator": name, "ambiguity_method": method, **p, "signals": list(fd.signals)}
        config["stop_s"] = None if np.isinf(p["stop_s"]) else p["stop_s"]
        return Solution(t=fd.t, quat_nb=None if single else out["quat"], euler=out["euler"], cov=out["cov"],
                        state_names=names, extras=extras, extra_units=dict(_UNITS), config=config)

    solve.__name__ = f"solve_{name}"
    return solve


def build_registry() -> dict:
    """The carrier-phase attitude solvers by name (``simkit.attitude.SOLVERS`` adds ``tdcp``)."""
    return {name: solver(name) for name in _METHOD}
