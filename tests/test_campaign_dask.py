"""Campaigns on real Dask clusters (loopback only, bounded, self-stopping): restart by content, failures recorded,
a scheduler and worker started as processes and used through ``--scheduler``, a worker killed midway."""
from __future__ import annotations

import json
import logging
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from cli_errors import run_cli
from simkit.campaign import run_campaign

pytestmark = pytest.mark.slow
SHORT = ["scenario.duration_s=20", "trajectory.segment[0].duration_s=20"]
ROOT = Path(__file__).resolve().parents[1]


def _records(run_dir: Path) -> dict:
    return {p.stem: json.loads(p.read_text()) for p in run_dir.glob("*.json")}


def test_restart_skips_verified_runs_redoes_tampered_ones_and_records_failures(tmp_path):
    out = tmp_path / "c"
    grid = ["gnss.elevation_mask_deg=10,89.9"]  # 89.9 deg: nothing rises, each of those runs fails when it runs
    s = run_campaign("xian_static_bds", out, runs=3, grid=grid, overrides=SHORT, workers=2)
    assert s["counts"] == {"planned": 6, "completed": 3, "failed": 3, "skipped": 0}
    assert all("elevation_mask_deg" in f["error"] for f in s["failures"])
    good = s["points"][0]
    assert good["completed"] == 3 and good["rates"]["ambiguity.ils"]["trials"] == 3 * 21
    r = good["rates"]["ambiguity.ils"]
    assert r["ci"][0] <= r["rate"] <= r["ci"][1]
    assert "imu_errors.gyro_white_rms" in good["statistics"]
    # swap two completed files: names are right, contents are not -> both are run again, nothing else is
    runs = out / "runs"
    a, b = runs / "p000_s000000.h5", runs / "p000_s000001.h5"
    a_bytes, b_bytes = a.read_bytes(), b.read_bytes()
    a.write_bytes(b_bytes), b.write_bytes(a_bytes)
    before = {k: v["sha256"] for k, v in _records(runs).items() if v["status"] == "ok"}
    s2 = run_campaign("xian_static_bds", out, runs=3, grid=grid, overrides=SHORT, workers=2)
    assert s2["counts"]["skipped"] == 1 and s2["counts"]["completed"] == 3 and s2["counts"]["failed"] == 3
    after = _records(runs)
    assert after["p000_s000002"]["sha256"] == before["p000_s000002"]
    assert s2["points"][0]["rates"] == s["points"][0]["rates"]  # same seeds and scenario: the same arrays
    assert not [p for p in runs.iterdir() if p.name.startswith(".")]


def _start(args, log):
    return subprocess.Popen([sys.executable, "-m", *args], stdout=log, stderr=subprocess.STDOUT,
                            env=dict(os.environ, PYTHONPATH=str(ROOT)), start_new_session=True)


def test_campaign_through_a_scheduler_and_worker_on_loopback(tmp_path):
    """``dask scheduler`` and ``dask worker`` as separate processes on 127.0.0.1 (self-stopping: the scheduler
    after 120 s idle, the worker 10 s after losing it), the xian_static_bds geometry through ``--scheduler``."""
    sched_file = tmp_path / "scheduler.json"
    log = open(tmp_path / "dask.log", "w")
    procs = [_start(["distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                     "--scheduler-file", str(sched_file), "--idle-timeout", "120"], log)]
    try:
        deadline = time.time() + 60
        while not sched_file.exists() and time.time() < deadline:
            time.sleep(0.2)
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        procs.append(_start(["distributed.cli.dask_worker", address, "--nthreads", "1", "--nworkers", "1",
                             "--no-dashboard", "--host", "127.0.0.1", "--death-timeout", "10"], log))
        args = ["campaign", "xian_static_bds", "--runs", "3", "--scheduler", address, "-o", "c", "-q"]
        for o in SHORT:
            args += ["--set", o]
        proc = run_cli(args, tmp_path, timeout=180)
        assert proc.returncode == 0, proc.stderr
        s = json.loads((tmp_path / "c" / "summary.json").read_text())
        assert s["cluster"] == address and s["counts"]["completed"] == 3
        r = s["points"][0]["rates"]["ambiguity.ils"]
        assert r["trials"] == 63 and r["ci"][0] <= r["rate"] <= r["ci"][1]
        workers = {rec["worker"] for rec in _records(tmp_path / "c" / "runs").values()}
        assert len(workers) == 1 and not workers & {f"{os.uname().nodename}:{os.getpid()}"}
    finally:
        for p in reversed(procs):
            p.send_signal(signal.SIGTERM)
        for p in reversed(procs):
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        log.close()


def test_200_runs_on_two_workers_survive_a_killed_worker_and_a_rerun_skips_all(tmp_path):
    """200 runs of a 20 s static scenario on 2 local worker processes; one worker is SIGKILLed after 40 runs
    (its nanny restarts it, Dask reschedules its task): no completed run is lost, the campaign finishes, and a
    re-run verifies and skips all 200."""
    from distributed import Client, LocalCluster

    out = tmp_path / "c"
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
        pids = list(client.run(os.getpid).values())
        killed = {}

        def kill_one_midway():
            deadline = time.time() + 300
            while time.time() < deadline and len(list((out / "runs").glob("*.json"))) < 40:
                time.sleep(0.05)
            killed["done_before"] = {p.stem: p.read_text() for p in (out / "runs").glob("*.json")}
            os.kill(pids[0], signal.SIGKILL)

        killer = threading.Thread(target=kill_one_midway, daemon=True)
        killer.start()
        s = run_campaign("xian_static_bds", out, runs=200, overrides=SHORT, scheduler=cluster.scheduler_address,
                         metrics=("imu_errors", "ambiguity"))
        killer.join(timeout=10)
    assert "done_before" in killed and len(killed["done_before"]) >= 40
    assert s["counts"] == {"planned": 200, "completed": 200, "failed": 0, "skipped": 0}
    records = _records(out / "runs")
    for run_id, text in killed["done_before"].items():  # completed before the kill: untouched
        assert json.loads(text)["sha256"] == records[run_id]["sha256"]
    assert len({r["worker"] for r in records.values()}) >= 3  # two workers plus the restarted one
    s2 = run_campaign("xian_static_bds", out, runs=200, overrides=SHORT, workers=2,
                      metrics=("imu_errors", "ambiguity"))
    assert s2["counts"]["skipped"] == 200 and s2["points"] == s["points"]


def _read_pty(fd: int, until: float) -> str:
    """Everything the child writes to its terminal until it closes it (EIO) or ``until`` (monotonic s)."""
    import select

    chunks = []
    while time.monotonic() < until:
        ready, _, _ = select.select([fd], [], [], 0.5)
        if not ready:
            continue
        try:
            data = os.read(fd, 65536)
        except OSError:  # EIO: the child closed its terminal
            break
        if not data:
            break
        chunks.append(data)
    return b"".join(chunks).decode(errors="replace")


def test_ctrl_c_on_a_campaign_is_one_line(tmp_path):
    """Regression: Ctrl-C in a terminal (SIGINT to the whole foreground group, workers included) printed about
    60 lines of Dask heartbeat tracebacks from the workers; now the command alone stops, in one line, exit 130."""
    import pty

    pid, fd = pty.fork()
    if pid == 0:  # the child: a real terminal is its controlling tty
        # as an interactive shell starts a command: a job started with & by a non-interactive shell (a CI script)
        # inherits SIGINT ignored, and Python then never turns Ctrl-C into KeyboardInterrupt
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        os.chdir(tmp_path)
        os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
        os.execv(sys.executable, [sys.executable, "-m", "simkit", "campaign", "quickstart", "--runs", "8", "-o",
                                  "c", "--set", "scenario.duration_s=28800"])   # ~30 s of work: still running
    try:
        deadline = time.monotonic() + 90
        while not (tmp_path / "c" / "runs").is_dir() and time.monotonic() < deadline:
            time.sleep(0.2)
        early = _read_pty(fd, time.monotonic() + 2)   # the workers are simulating now
        os.write(fd, b"\x03")                          # Ctrl-C, as typed
        text = early + _read_pty(fd, time.monotonic() + 60)
    finally:
        _, status = os.waitpid(pid, 0)
    bar = re.compile(r"^campaign:\s+\d+%")  # the progress bar's own redraws
    plain = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", text).replace("^C", "")  # terminal attribute resets
    lines = [ln for ln in plain.replace("\r", "\n").splitlines() if ln.strip() and not bar.match(ln)]
    assert os.waitstatus_to_exitcode(status) == 130, text
    assert lines == ["simkit campaign: interrupted"], text
