"""``simkit.run``: the one place that wires the stages together.

scenario -> trajectory truth -> IMU -> (sky from the constellation stage) -> GNSS observables -> one HDF5 file,
block by block. Each stage takes and returns arrays and small dataclasses; this module maps them to the dataset
paths that ``simkit/io/schema.py`` declares.
"""
from __future__ import annotations

import json
from collections import deque
from dataclasses import dataclass, fields
from pathlib import Path
from typing import TYPE_CHECKING, Iterator

import numpy as np

from . import gpstime
from .errors import DataFileError, OutputError, ScenarioError
from .heap import keep_freed_memory
from .imu import ImuSimulator
from .io.output import check_output
from .io.writer import Writer
from .lane import Lane, default_threads
from .scenario import Scenario, load, resolve
from .trajectory import Trajectory

if TYPE_CHECKING:  # the GNSS stages are imported when a scenario has [gnss]: a truth + IMU run starts 0.5 s sooner
    from .constellation import Sky
    from .gnss import GnssSimulator

BLOCK_SAMPLES = 1 << 16
TRUTH_AHEAD = 2  # truth blocks computed ahead of the IMU and the writes (12 MB each at 65,536 samples)
GNSS_CELLS = 1 << 20  # ~8 MB per (M, A, S) float array handed from the GNSS stage to the writer
MAX_OUTPUT_BYTES = 100 * 2**30  # refuse larger runs unless forced: a typo in duration_s, not a dataset
_SKY_CHECK_STEP_S = 60.0
_SKY_CHECK_MAX = 1440


@dataclass(frozen=True)
class Stages:
    """The stages of one run, built from a scenario."""

    trajectory: Trajectory
    imu: ImuSimulator | None
    gnss: GnssSimulator | None


def run(scenario, out=None, seed=None, overrides=None, progress=False, block_samples: int = BLOCK_SAMPLES,
        force: bool = False, threads: int | None = None) -> Path:
    """Simulate a scenario into ``out`` (default ``<scenario name>.h5``); returns the output path.

    ``threads``: threads sharing the work, the calling thread included (1: all of it on the calling thread;
    default :func:`simkit.lane.default_threads`): the truth computed ahead and the output's compression run on
    the others, and on the calling thread while it waits for them.

    Everything that can be checked is checked before the first sample: the scenario, the constellation sources
    and their coverage of the run, the output path (an existing file is replaced only when it is a simkit file
    without /solutions), and the output size (refused above the free disk space or :data:`MAX_OUTPUT_BYTES`);
    ``force`` overrides the last two. The process keeps freed heap memory for the next block
    (:func:`simkit.heap.keep_freed_memory`; glibc only, the user's ``MALLOC_*_`` tunables stand).
    """
    keep_freed_memory()
    sc = load(scenario, assignments(overrides), seed=seed)
    out = Path(out) if out is not None else Path(f"{sc.name}.h5")
    sky = _sky(sc) if sc.gnss is not None else None
    size = estimate_bytes(sc, len(sky.sat_ids) if sky is not None else 0)
    if size > MAX_OUTPUT_BYTES and not force:
        raise OutputError(out, f"the run would write about {size / 2**30:.0f} GiB (limit {MAX_OUTPUT_BYTES / 2**30:.0f}"
                          f" GiB; scenario.duration_s = {sc.duration_s:g}); --force to run it anyway")
    source = None if isinstance(scenario, dict) else _scenario_file(scenario)
    check_output(out, inputs=[source, *sc.inputs], estimated_bytes=size, force=force, simkit_only=True)
    threads = default_threads() if threads is None else threads
    traj = Trajectory(sc.trajectory, sc.duration_s)
    # the truth starts now, on the lane, while the IMU and GNSS stages are built and h5py loads
    with Lane(threads - 1) as lane:
        truth = _truth_blocks(traj.blocks(block_samples=block_samples), lane)
        stages = build(sc, sky, traj)
        with Writer(out, root_attributes(sc), lane=lane) as w:
            _write(w, sc, stages, truth, progress, ahead=lane.workers > 0, imu_ahead=TRUTH_AHEAD * block_samples)
    return out


def assignments(overrides) -> list[str]:
    """``overrides`` as ``--set`` items: a list of "dotted.key=value" strings as given, or a dict of
    {dotted.key: value} (nested dicts are tables: ``{"imu": {"preset": "ideal"}}`` is ``imu.preset``), each value
    written as the TOML literal the command line would take."""
    if overrides is None or isinstance(overrides, (list, tuple)):
        return list(overrides or [])
    if not isinstance(overrides, dict):
        raise ScenarioError("overrides", f"expected a dict {{dotted.key: value}} or a list of 'key=value', got "
                            f"{type(overrides).__name__}")
    out = []
    for key, value in overrides.items():
        if isinstance(value, dict) and value:
            out += assignments({f"{key}.{k}": v for k, v in value.items()})
        else:
            out.append(f"{key}={toml_literal(key, value)}")
    return out


def toml_literal(key: str, value) -> str:
    """``value`` as a one-line TOML literal (inline tables and arrays); a value TOML cannot hold (None, an
    object) is an error naming ``key``."""
    import tomli_w

    if isinstance(value, dict):
        items = (f"{tomli_w.dumps({k: 0})[:-5]} = {toml_literal(key, v)}" for k, v in value.items())  # quoted keys
        return "{ " + ", ".join(items) + " }"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_literal(key, v) for v in value) + "]"
    try:
        return tomli_w.dumps({"v": value.item() if hasattr(value, "item") else value})[4:].rstrip("\n")
    except TypeError:
        raise ScenarioError(key, f"expected a TOML value (number, string, boolean, array, table), got "
                            f"{value!r}") from None


def build(sc: Scenario, sky: Sky | None = None, traj: Trajectory | None = None) -> Stages:
    """The stages of scenario ``sc``; ``sky`` (loaded from ``sc.gnss`` when not given) is first checked to
    cover the run; ``traj``: the scenario's trajectory when already made."""
    traj = traj if traj is not None else Trajectory(sc.trajectory, sc.duration_s)
    imu = ImuSimulator(sc.imu, sc.trajectory.rate_hz, sc.seed) if sc.imu is not None else None
    gnss = None
    if sc.gnss is not None:
        from .environment import Environment
        from .gnss import GnssSimulator

        sky = sky if sky is not None else _sky(sc)
        _check_sky_covers_run(sc, sky, next(traj.blocks(block_samples=1)).pos_ecef[0])
        env = None
        if sc.environment is not None:
            tr = sc.trajectory
            env = Environment(sc.environment, (tr.lat_rad, tr.lon_rad, tr.height_m),
                              np.array([a.lever_arm_b for a in sc.gnss.antennas]))
        gnss = GnssSimulator(sc.gnss, sky, sc.start_week, sc.start_sow, sc.seed, sc.duration_s, env)
    return Stages(traj, imu, gnss)


def root_attributes(sc: Scenario) -> dict:
    return {"scenario_toml": sc.text, "seed": str(sc.seed) if sc.seed >= 2**63 else sc.seed,
            "start_gps_week": sc.start_week, "start_gps_sow": sc.start_sow, "scenario_name": sc.name,
            "overrides": json.dumps(list(sc.overrides))}


def estimate_bytes(sc: Scenario, n_sats: int) -> float:
    """An upper bound of the uncompressed output size (bytes), from the configuration alone."""
    n = sc.duration_s * sc.trajectory.rate_hz + 1
    total = n * 23 * 8                                           # /truth: t + 6 vectors + quaternion
    if sc.imu is not None:
        total += n * (13 + 3 * 16) * 8                           # t, rates, increments, up to 16 error terms
    if sc.gnss is not None:
        m = sc.duration_s * sc.gnss.rate_hz + 1
        a, k = len(sc.gnss.antennas), len(sc.gnss.signals)
        total += m * (4 * n_sats + a * (8 + 10 * n_sats) + k * a * n_sats * 16) * 8
    return float(total)


def _scenario_file(scenario) -> Path | None:
    try:
        return resolve(scenario)
    except ScenarioError:
        return None


def _sky(sc: Scenario) -> Sky:
    """The constellation stage: load the sources, refuse duplicates and a sky with nothing to see."""
    from .constellation import load_sky

    try:
        sky = load_sky(sc.gnss.sources, sc.gnss.nav_systems)
    except DataFileError as exc:
        index = next((i for i, s in enumerate(sc.gnss.sources) if str(s) in exc.path or exc.path in str(s)), 0)
        raise ScenarioError(f"gnss.constellation[{index}].source", str(exc), sc.source) from None
    if sky.duplicates:
        raise ScenarioError("gnss.constellation", f"satellites loaded twice: {', '.join(sky.duplicates)}", sc.source)
    return sky


def _check_sky_covers_run(sc: Scenario, sky: Sky, origin: np.ndarray) -> None:
    """One clear error when no satellite has a state, or none rises above the mask, at the start position
    ``origin`` (3,) m ECEF during the run (sampled every minute)."""
    from .constellation import NoStateError

    t = np.linspace(0.0, sc.duration_s, int(min(sc.duration_s // _SKY_CHECK_STEP_S, _SKY_CHECK_MAX)) + 2)
    week, sow = gpstime.add_seconds(sc.start_week, sc.start_sow, t)
    for i, const in enumerate(sky.constellations):
        try:
            const.require_states(week, sow)
        except NoStateError as exc:
            raise ScenarioError(f"gnss.constellation[{i}].source", str(exc), sc.source) from None
    with np.errstate(invalid="ignore"):
        el = sky.view(np.broadcast_to(origin, (t.size, 3)), week, sow)["elevation"]
    mask = sc.gnss.elevation_mask_rad
    if not (el >= mask).any():
        raise ScenarioError("gnss.elevation_mask_deg", f"no satellite of {', '.join(sky.sources)} rises above "
                            f"{np.degrees(mask):g} deg at the origin during the run", sc.source)


def _rows(prefix: str, obj) -> dict[str, np.ndarray]:
    """Dataset path -> array for every field of a stage's dataclass."""
    return {f"{prefix}/{f.name}": getattr(obj, f.name) for f in fields(obj) if getattr(obj, f.name) is not None}


def gnss_rows(ep, prefix: str = "gnss/") -> dict[str, np.ndarray]:
    """Dataset path -> array of a block of :class:`simkit.gnss.GnssEpochs` (``prefix`` "" gives paths
    relative to /gnss)."""
    rows = {f"{prefix}t": ep.t, f"{prefix}sat_pos_ecef": ep.sat_pos_ecef, f"{prefix}sat_clock": ep.sat_clock}
    rows.update(_rows(f"{prefix}truth", ep.truth))
    for name, obs in ep.obs.items():
        rows.update(_rows(f"{prefix}obs/{name}", obs))
    for name, truth in ep.signal_truth.items():
        rows.update(_rows(f"{prefix}truth/{name}", truth))
    return rows


def gnss_static_rows(st, prefix: str = "gnss/") -> dict[str, np.ndarray]:
    """Dataset path -> array of :class:`simkit.gnss.GnssStatic`."""
    return {(f"{prefix}antennas/{f.name}" if f.name in ("lever_arm_b", "boresight_b") else f"{prefix}{f.name}"):
            getattr(st, f.name) for f in fields(st) if getattr(st, f.name) is not None}


def _imu_rows(t, block) -> dict[str, np.ndarray]:
    rows = {"imu/t": t, "imu/gyro": block.gyro, "imu/accel": block.accel}
    if block.dtheta is not None:
        rows["imu/dtheta"], rows["imu/dvel"] = block.dtheta, block.dvel
    rows.update({f"imu/errors/{name}": data for name, data in block.errors.items()})
    return rows


def _write_static(w: Writer, sc: Scenario, stages: Stages) -> None:
    truth_attrs = {"rate_hz": sc.trajectory.rate_hz}
    if sc.trajectory.path is not None:      # a logged trajectory: which log, and what the fit found
        truth_attrs["log"] = sc.trajectory.path.summary()
    w.group_attrs("truth", truth_attrs)
    if stages.imu is not None:
        w.group_attrs("imu", dict(stages.imu.attributes(), rate_hz=sc.trajectory.rate_hz))
    if stages.gnss is not None:
        w.group_attrs("gnss", {"rate_hz": sc.gnss.rate_hz})
        for path, data in gnss_static_rows(stages.gnss.static()).items():
            w.write(path, data)


def _truth_blocks(blocks: Iterator, lane: Lane, depth: int = TRUTH_AHEAD) -> Iterator:
    """The truth blocks as an iterator, computed on ``lane`` from this call on and up to ``depth`` blocks ahead of
    the reader (numpy releases the GIL in its loops, so the truth, the IMU + writes and the compression share the
    cores; while the reader waits for a block, it compresses); in order, as computed alone. A lane without workers:
    ``blocks`` itself, computed by the reader on its thread. Jobs still queued when the run stops early are the
    lane's to cancel."""
    if not lane.workers:
        return blocks
    queued = deque(lane.submit(next, blocks, None, key="truth") for _ in range(depth))

    def read() -> Iterator:
        while (block := lane.wait(queued.popleft())) is not None:
            queued.append(lane.submit(next, blocks, None, key="truth"))
            yield block

    return read()


def _write(w: Writer, sc: Scenario, stages: Stages, truth: Iterator, progress: bool, ahead: bool = False,
           imu_ahead: int = 0) -> None:
    """Every block of the run into ``w``: truth and IMU rows per ``truth`` block, then the GNSS epochs of each block
    (``ahead``: the next GNSS slice's geometry on a worker thread, and the IMU noise of the first ``imu_ahead``
    samples drawn while the lane computes the first truth blocks: this thread would wait for them idle)."""
    _write_static(w, sc, stages)
    if ahead and stages.imu is not None:
        stages.imu.draw_ahead(min(imu_ahead, stages.trajectory.n_samples()))
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=stages.trajectory.n_samples(), unit="sample", unit_scale=True, desc=sc.name, leave=False)
    try:
        blocks = _truth_rows(w, stages, truth, bar)
        if stages.gnss is None:
            for _ in blocks:
                pass
            return
        for ep in stages.gnss.process_blocks(_gnss_slices(sc, stages.gnss, blocks), ahead=ahead):
            for path, data in gnss_rows(ep).items():
                w.append(path, data)
    finally:
        if bar is not None:
            bar.close()


def _truth_rows(w: Writer, stages: Stages, blocks: Iterator, bar) -> Iterator:
    """The truth blocks, each written (truth and IMU rows) before it is handed on."""
    for truth in blocks:
        rows = _rows("truth", truth)
        if stages.imu is not None:
            rows.update(_imu_rows(truth.t, stages.imu.process(truth.t, truth.omega_ib_b, truth.f_ib_b)))
        for path, data in rows.items():
            w.append(path, data, handed_over=True)  # fresh arrays of this block, never written to again
        yield truth
        if bar is not None:
            bar.update(len(truth.t))


def _gnss_slices(sc: Scenario, gnss: GnssSimulator, blocks: Iterator) -> Iterator[tuple]:
    """The GNSS epochs of the truth blocks (every ``rate_hz / gnss.rate_hz``-th sample) as the arguments of
    :meth:`GnssSimulator.process`, in slices of at most :data:`GNSS_CELLS` (epoch, antenna, satellite, signal)
    cells, so memory stays bounded when the GNSS rate approaches the truth rate."""
    stride = int(round(sc.trajectory.rate_hz / sc.gnss.rate_hz))
    per_epoch = gnss.n_ant * len(gnss.sat_ids) * len(gnss.signals)
    step = max(1, GNSS_CELLS // max(1, per_epoch))
    k = 0
    for truth in blocks:
        idx = np.nonzero((np.arange(k, k + len(truth.t)) % stride) == 0)[0]
        k += len(truth.t)
        for start in range(0, idx.size, step):
            sub = truth.take(idx[start:start + step])
            yield sub.t, sub.pos_ecef, sub.vel_ecef(), sub.quat_nb, sub.omega_ib_b
