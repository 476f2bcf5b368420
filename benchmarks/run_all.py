"""Run every benchmark that has a peer (and the cold start), and write one table into docs/benchmarks.md.

    python benchmarks/run_all.py [--quick] [--only NAME ...] [--no-write]      (or: python -m benchmarks ...)

For each figure the table gives simkit's value, the peer's value measured in the same run, the ratio, the date,
the machine load (1-minute load average before and after that benchmark) and the machine. A peer that is not
installed (or a gnss-ins-sim checkout not found: ``GNSS_INS_SIM=DIR``) is said so in its row; a benchmark that
fails says so with its error. ``--quick`` runs shorter records (same code paths, noisier figures); the table says
which mode made it. The table is written between the markers below in docs/benchmarks.md; --no-write prints only.
"""
from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT))

import timing  # noqa: E402

DOC = ROOT / "docs" / "benchmarks.md"
BEGIN, END = "<!-- run_all: begin -->", "<!-- run_all: end -->"
ABSENT = "peer absent"


def _peer_missing(exc: Exception) -> str:
    return f"{ABSENT} ({type(exc).__name__}: {exc})"


def truth_imu(quick: bool):
    import bench_truth_imu

    r = bench_truth_imu.measure(60.0 if quick else 600.0)
    rows = bench_truth_imu.report(r)
    if r["peer"] is None:
        rows = [(name, ours, f"{ABSENT} (gnss-ins-sim checkout: GNSS_INS_SIM=DIR)", ratio)
                for name, ours, _, ratio in rows]
    return rows


def truth(quick: bool):
    import bench_truth
    import peers

    seconds = 600.0 if quick else 3600.0
    with_write, alone, _ = bench_truth.ours(seconds, 1000.0)
    pathgen = peers.gnss_ins_sim()
    name = f"truth, {seconds:g} s at 1 kHz (samples/s)"
    if pathgen is None:
        return [(f"{name}, generation alone", f"{alone:,.0f}", f"{ABSENT} (GNSS_INS_SIM=DIR)", "-"),
                (f"{name}, with the HDF5 write", f"{with_write:,.0f}", f"{ABSENT} (GNSS_INS_SIM=DIR)", "-")]
    peer = bench_truth.gnss_ins_sim_rate(pathgen, 10.0 if quick else 40.0, 1000.0)
    return [(f"{name}, generation alone; peer: path_gen", f"{alone:,.0f}", f"{peer:,.0f}", f"{alone / peer:.0f}x"),
            (f"{name}, with the HDF5 write", f"{with_write:,.0f}", f"{peer:,.0f}", f"{with_write / peer:.0f}x")]


def imu(quick: bool):
    import tempfile

    import bench_imu
    import peers

    n = int((0.1 if quick else 1.0) * 3600 * bench_imu.RATE)
    with tempfile.TemporaryDirectory() as tmp:
        bench_imu.run_ours(2000, Path(tmp) / "w.h5", "none", False)
        t_imu, t_write, _, _ = bench_imu.run_ours(n, Path(tmp) / "imu.h5", "none", False)
    ours = 6 * n / t_imu
    name = f"IMU errors, {n / 3.6e6:g} h at 1 kHz, every term (M axis-samples/s); peer: gyro_gen + acc_gen"
    pathgen = peers.gnss_ins_sim()
    if pathgen is None:
        return [(name, f"{ours / 1e6:.1f}", f"{ABSENT} (GNSS_INS_SIM=DIR)", "-")]
    peer = bench_imu.gnss_ins_sim_rate(pathgen, 200_000)
    return [(name, f"{ours / 1e6:.1f}", f"{peer / 1e6:.2f}", f"{ours / peer:.0f}x")]


def allan(quick: bool):
    import numpy as np

    from simkit.imu.allan import adev

    y = np.random.default_rng(2).standard_normal(200_000 if quick else 2_000_000)
    taus = np.logspace(-3, 2.5, 30)
    ours = timing.best_of(lambda: adev(y, 1e-3, taus), 3)
    name = f"overlapping Allan deviation, {y.size:,} samples, 30 taus (s)"
    try:
        import allantools
    except ImportError as exc:
        return [(name, f"{ours:.3f}", _peer_missing(exc), "-")]
    peer = timing.best_of(lambda: allantools.oadev(y, rate=1000.0, data_type="freq", taus=taus), 3)
    return [(f"{name}; peer: allantools.oadev", f"{ours:.3f}", f"{peer:.3f}", f"{peer / ours:.1f}x")]


def gnss(quick: bool):
    import bench_gnss

    hours = 1.0 if quick else 24.0
    bench_gnss.ours(0.05)  # compiled kernels loaded: the figure is the steady state
    sec, cpu, _, n_sats, n_obs = bench_gnss.ours(hours)
    name = (f"GNSS observables, {hours:g} h at 1 Hz, {n_sats} satellites (GPS+BDS), 3 antennas, 2 signals per "
            f"satellite (s wall; {cpu:.1f} s CPU); peer: gnss-lib-py simulate_measures on the same (epoch, antenna, "
            "satellite) triples, in its own venv (GNSS_LIB_PY_PYTHON)")
    try:
        per = bench_gnss.peer()
    except Exception as exc:  # the peer is optional
        return [(name, f"{sec:.1f}", _peer_missing(exc), "-")]
    if per is None:
        return [(name, f"{sec:.1f}", f"{ABSENT} (no RINEX navigation file)", "-")]
    peer_sec = per * n_obs / 2   # two signals per satellite: (epoch, antenna, satellite) triples
    return [(name, f"{sec:.1f}", f"{peer_sec:.0f}", f"{peer_sec / sec:.1f}x")]


def kf(quick: bool):
    import bench_kf

    imu_data, fixes, init = bench_kf.data((0.1 if quick else 1.0) * 3600.0)
    wall, _ = bench_kf.ours(imu_data, fixes, init)
    ours = imu_data.t.size / wall
    name = "kf15 loosely coupled, 100 Hz IMU + 1 Hz fixes (samples/s); peer: pyins run_feedback_filter"
    try:
        pw, pn = bench_kf.pyins_run(imu_data, fixes, init, 20.0 if quick else 60.0)
    except ImportError as exc:
        return [(name, f"{ours:,.0f}", _peer_missing(exc), "-")]
    return [(name, f"{ours:,.0f}", f"{pn / pw:,.0f}", f"{ours / (pn / pw):,.0f}x")]


def lambda_(quick: bool):
    import math

    import bench_lambda

    try:
        rows = bench_lambda.measure((10, 20, 40), 8 if quick else 30)
    except ImportError as exc:
        return [("ILS, n = 10, 20, 40 (us per solve)", "-", _peer_missing(exc), "-")]
    out = []
    for n, ms, mr, mc in rows:
        cssr = f"cssrlib {mc:.0f}" if not math.isnan(mc) else f"cssrlib: {ABSENT}"
        ratio = f"C/simkit {mr / ms:.2f}" + (f", cssrlib/simkit {mc / ms:.0f}" if not math.isnan(mc) else "")
        out.append((f"ILS n = {n}, 2 candidates (us per solve); peers: RTKLIB lambda (C), cssrlib mlambda",
                    f"{ms:.1f}", f"C {mr:.1f}, {cssr}", ratio))
    return out


def campaign(quick: bool):
    import bench_campaign

    runs, duration = (4, 600.0) if quick else (12, 3600.0)
    r = bench_campaign.measure(runs, duration, 1 if quick else 2)
    name = f"campaign, {runs} runs x {duration:g} s of xian_static_bds (s)"
    return [(f"{name}: 2 Dask workers; peer: ProcessPoolExecutor, 2 processes", f"{r['two_workers_s']:.2f}",
             f"{r['pool_s']:.2f}", f"{r['pool_s'] / r['two_workers_s']:.2f}x"),
            (f"{name}: speed-up 1 -> 2 Dask workers (no peer: our own 1 worker, same run)",
             f"{r['one_worker_s']:.2f} -> {r['two_workers_s']:.2f}", "no peer",
             f"{r['one_worker_s'] / r['two_workers_s']:.2f}x")]


def cold_start(quick: bool):
    import bench_cold_start

    rows = {r["state"]: r for r in bench_cold_start.measure(1 if quick else 3)}
    cold, warm = rows["cold"], rows["warm"]
    return [("first `simkit run quickstart`, empty numba cache vs warm (s; no peer)",
             f"{cold['quickstart']:.1f} vs {warm['quickstart']:.1f}", "no peer", "-"),
            ("first `simkit solve quickstart.h5`, empty numba cache vs warm (s; no peer)",
             f"{cold['solve']:.1f} vs {warm['solve']:.1f}", "no peer", "-")] + _cold_start_prepared()


def _cold_start_prepared():
    """The same first runs seeded from the prepared kernels (simkit/_jit, what `pip install .` ships)."""
    import bench_cold_start

    from simkit import jitcache
    name = "first `simkit run quickstart` / `simkit solve quickstart.h5`, empty numba cache, prepared kernels (s)"
    if not jitcache.prepared_matches(str(jitcache.PREPARED)):
        return [(name, "not run: no prepared cache for these sources (python -m simkit compile)", "no peer", "-")]
    bench_cold_start.PREPARED = True
    try:
        cold = {r["state"]: r for r in bench_cold_start.measure(1)}["cold"]
    finally:
        bench_cold_start.PREPARED = False
    return [(name, f"{cold['quickstart']:.1f} / {cold['solve']:.1f}", "no peer", "-")]


BENCHMARKS = {"truth_imu": truth_imu, "truth": truth, "imu": imu, "allan": allan, "gnss": gnss, "kf": kf,
              "lambda": lambda_, "campaign": campaign, "cold_start": cold_start}


def machine() -> str:
    model = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} cores, Python {platform.python_version()}"


def run(names, quick: bool) -> list[tuple]:
    """[(benchmark, figure, simkit, peer, ratio, date, load)] for the benchmarks ``names``, in order."""
    out = []
    for name in names:
        load0, t0 = os.getloadavg()[0], time.perf_counter()
        try:
            rows = BENCHMARKS[name](quick)
        except Exception as exc:  # one benchmark failing does not stop the others; its row says why
            rows = [("(did not run)", f"failed: {type(exc).__name__}: {exc}", "-", "-")]
        load = f"{load0:.1f} / {os.getloadavg()[0]:.1f}"
        date = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M")
        for figure, ours, peer, ratio in rows:
            out.append((name, figure, ours, peer, ratio, date, load))
        print(f"[{name}: {time.perf_counter() - t0:.0f} s]", file=sys.stderr)
    return out


def markdown(rows, quick: bool) -> str:
    head = (f"{BEGIN}\nWritten by `python benchmarks/run_all.py{' --quick' if quick else ''}` "
            f"({'quick: shorter records' if quick else 'full records'}) on {machine()}. Each peer figure is "
            "measured in the same run as ours; load = 1-minute load average before / after that benchmark.\n\n"
            "| benchmark | figure | simkit | peer (same run) | ratio | date (UTC) | load |\n"
            "|---|---|---|---|---|---|---|\n")
    body = "".join("| " + " | ".join(str(c).replace("|", "/") for c in r) + " |\n" for r in rows)
    return head + body + END


def previous_rows(doc: Path = DOC) -> list[tuple]:
    """The rows of the table now between the markers of ``doc`` (none when absent)."""
    text = doc.read_text()
    if BEGIN not in text or END not in text:
        return []
    lines = text[text.index(BEGIN):text.index(END)].splitlines()
    cells = [tuple(c.strip() for c in line.strip().strip("|").split("|")) for line in lines if line.startswith("| ")]
    return [c for c in cells[1:] if len(c) == 7]                     # past the header row


def write(text: str, doc: Path = DOC) -> None:
    """Replace the text between the markers in ``doc`` (appended with a heading when the markers are absent)."""
    old = doc.read_text()
    if BEGIN in old and END in old:
        new = old[:old.index(BEGIN)] + text + old[old.index(END) + len(END):]
    else:
        new = old.rstrip("\n") + "\n\n## Last full run (`python benchmarks/run_all.py`)\n" + text + "\n"
    tmp = doc.with_name(f".{doc.name}.tmp")
    tmp.write_text(new)
    os.replace(tmp, doc)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="shorter records: minutes instead of tens of minutes")
    ap.add_argument("--only", nargs="+", choices=sorted(BENCHMARKS),
                    help="run these benchmarks only; the table keeps the other benchmarks' rows from the last run")
    ap.add_argument("--no-write", action="store_true", help="print the table, leave docs/benchmarks.md alone")
    args = ap.parse_args(argv)
    rows = run(args.only or list(BENCHMARKS), args.quick)
    if args.only:  # the other benchmarks keep their rows (and dates) from the last run
        kept = [r for r in previous_rows() if r[0] not in args.only]
        order = list(BENCHMARKS)
        rows = sorted(kept + rows, key=lambda r: order.index(r[0]) if r[0] in order else len(order))
    timing.print_table(["benchmark", "figure", "simkit", "peer (same run)", "ratio", "date (UTC)", "load"], rows)
    if not args.no_write:
        write(markdown(rows, args.quick))
        print(f"table written to {DOC.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
