"""Body-frame lines of sight for the validation: from a scenario (geometry only, no file) or a simkit file.

The Gramian of eq. (16) takes one line of sight per satellite for all antennas (parallel rays: over 10 m
baselines and 20,000 km ranges the directions differ by < 1e-6 rad), taken from the master antenna (scenario:
the trajectory's reference point, file: antenna 0) and rotated ECEF -> ENU -> body with the true attitude.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial.transform import Rotation

from .. import gpstime
from ..constellation.geometry import lines_of_sight_enu
from ..io import has, path_of, read_gnss, read_truth, truth_at
from .errors import ValidationInputError


@dataclass(frozen=True)
class ValidationGeometry:
    """What the validation needs, at M epochs and S satellites.

    ``t`` (M,) s since the start (GPS time ``week``, ``sow0`` s); ``sat_ids`` (S,); ``los_b`` (M, S, 3) unit
    vectors antenna -> satellite in the body frame; ``elevation`` (M, S) rad; ``visible`` (M, S) bool;
    ``lever_arms_b`` (A, 3) m antenna phase centres in the body frame; ``source`` a label for reports.
    """

    t: np.ndarray
    week: int
    sow0: float
    sat_ids: tuple
    los_b: np.ndarray
    elevation: np.ndarray
    visible: np.ndarray
    lever_arms_b: np.ndarray
    source: str

    def configurations(self) -> dict[str, np.ndarray]:
        """Baselines (B, 3) m from antenna 0: ``dual`` (antennas 0-1) and, with 3+ antennas, ``three``."""
        b = self.lever_arms_b[1:] - self.lever_arms_b[0]
        out = {"dual": b[:1]}
        if len(b) >= 2:
            out["three"] = b[:2]
        return out


def body_los(sat_pos_ecef, rx_pos_ecef, quat_nb) -> tuple[np.ndarray, np.ndarray]:
    """Unit lines of sight (M, S, 3) in the body frame and elevations (M, S) rad, from satellites ``sat_pos_ecef``
    (M, S, 3) m, receiver ``rx_pos_ecef`` (M, 3) m and attitude ``quat_nb`` (M, 4) body -> ENU, scalar last."""
    u_enu, el = lines_of_sight_enu(rx_pos_ecef, sat_pos_ecef)
    C_bn = Rotation.from_quat(quat_nb).inv().as_matrix()           # (M, 3, 3) C_n^b
    return np.einsum("mij,msj->msi", C_bn, u_enu), el


BLOCK_EPOCHS = 3600  # epochs of sky geometry at a time: peak memory ~ BLOCK_EPOCHS x satellites x 1 kB


def from_scenario(sc, progress: bool = False, block_epochs: int = BLOCK_EPOCHS) -> ValidationGeometry:
    """Geometry of scenario ``sc`` (a loaded :class:`simkit.scenario.Scenario`) at its GNSS rate: trajectory truth
    and the sky of ``sc.gnss.sources``; visible = elevation at or above ``sc.gnss.elevation_mask_rad``.

    Streamed: the light-time geometry (several (M, S, 3) arrays) is computed ``block_epochs`` epochs at a time
    and only the lines of sight, elevations and visibility of the whole run are kept; every epoch is computed
    on its own, so the result does not depend on the block size."""
    from ..constellation import load_sky
    from ..trajectory import Trajectory

    if sc.gnss is None:
        raise ValidationInputError(f"{sc.source or sc.name}: [gnss]: the scenario has no GNSS section to validate")
    if len(sc.gnss.antennas) < 2:
        raise ValidationInputError(f"{sc.source or sc.name}: gnss.antenna: expected at least 2 antennas (a "
                                   f"baseline), found {len(sc.gnss.antennas)}")
    traj = Trajectory(sc.trajectory, sc.duration_s)
    sky = load_sky(sc.gnss.sources, sc.gnss.nav_systems)
    m, n_sat = traj.n_samples(sc.gnss.rate_hz), len(sky.sat_ids)
    t, los, el = np.empty(m), np.empty((m, n_sat, 3)), np.empty((m, n_sat))
    k = 0
    for block in traj.blocks(rate_hz=sc.gnss.rate_hz, block_samples=block_epochs):
        rows = slice(k, k + block.t.size)
        week, sow = gpstime.add_seconds(sc.start_week, sc.start_sow, block.t)
        with np.errstate(invalid="ignore"):
            sat_pos = sky.view(block.pos_ecef, week, sow)["sat_pos"]
        t[rows] = block.t
        los[rows], el[rows] = body_los(sat_pos, block.pos_ecef, block.quat_nb)
        k += block.t.size
    with np.errstate(invalid="ignore"):
        vis = np.isfinite(el) & (el >= sc.gnss.elevation_mask_rad)
    arms = np.array([a.lever_arm_b for a in sc.gnss.antennas], dtype=float)
    return ValidationGeometry(t, int(sc.start_week), float(sc.start_sow), tuple(sky.sat_ids), los, el, vis, arms,
                    f"scenario {sc.name} ({', '.join(sky.sources)})")


NEEDED = (("gnss", "t"), ("gnss", "sat_pos_ecef"), ("gnss_truth", "antenna_pos_ecef"), ("antennas", "lever_arm_b"),
          ("truth", "t"), ("truth", "quat_nb"), ("gnss", "sat_id"))


def from_file(ds) -> ValidationGeometry:
    """Geometry of an open simkit file ``ds`` (:func:`simkit.open`): /gnss/sat_pos_ecef, antenna 0 of
    /gnss/truth/antenna_pos_ecef, /truth/quat_nb interpolated (slerp) to /gnss/t; visible = the satellite's
    carrier is tracked at every antenna on the first signal (else elevation above 0)."""
    missing = [path_of(g, n) for g, n in NEEDED if not has(ds, g, n)]
    if missing:
        raise ValidationInputError(f"{ds.path}: /{missing[0]}: missing; the validation needs "
                                   f"{', '.join(path_of(g, n) for g, n in NEEDED)}")
    signals = ds.groups(path_of("obs"))
    g = read_gnss(ds, signals=signals[:1], obs=("carrier",) if signals else (), truth=("antenna_pos_ecef",))
    t, rx = g.t, g.truth["antenna_pos_ecef"][:, 0, :]
    truth = read_truth(ds, fields=("quat_nb",), required=("quat_nb",))
    quat = truth_at(truth, np.clip(t, truth.t[0], truth.t[-1])).quat_nb
    los, el = body_los(g.sat_pos_ecef, rx, quat)
    if signals:
        vis = np.isfinite(g.obs["carrier"][signals[0]]).all(axis=1)
    else:
        vis = np.isfinite(el) & (el > 0)
    arms = g.lever_arm_b
    if len(arms) < 2:
        raise ValidationInputError(f"{ds.path}: /gnss/antennas/lever_arm_b: expected at least 2 antennas, found "
                                   f"{len(arms)}")
    return ValidationGeometry(t, int(ds.attrs.get("start_gps_week", 0)), float(ds.attrs.get("start_gps_sow", 0.0)),
                              tuple(g.sat_id.tolist()), los, el, vis & np.isfinite(el), arms,
                              f"file {ds.path.name} (scenario {ds.scenario_name})")


def select_systems(geo: ValidationGeometry, systems: str) -> ValidationGeometry:
    """``geo`` restricted to the satellites whose id starts with one of ``systems`` (e.g. "C" for BDS, "G,C")."""
    letters = {s.strip().upper() for s in systems.split(",") if s.strip()}
    keep = np.array([sid[:1].upper() in letters for sid in geo.sat_ids], bool)
    if not keep.any():
        found = sorted({sid[:1] for sid in geo.sat_ids})
        raise ValidationInputError(f"--systems: no satellite of system(s) {systems!r}; the sky has "
                                   f"{', '.join(found)}")
    return replace(geo, sat_ids=tuple(np.array(geo.sat_ids)[keep].tolist()), los_b=geo.los_b[:, keep],
                   elevation=geo.elevation[:, keep], visible=geo.visible[:, keep],
                   source=f"{geo.source}, systems {','.join(sorted(letters))}")


def every_nth(geo: ValidationGeometry, step: int) -> ValidationGeometry:
    """``geo`` at every ``step``-th epoch (the same object for step 1)."""
    if step == 1:
        return geo
    return replace(geo, t=geo.t[::step], los_b=geo.los_b[::step], elevation=geo.elevation[::step],
                   visible=geo.visible[::step])
