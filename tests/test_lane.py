"""simkit.lane.Lane: jobs in submission order, one at a time per key, and the waiting thread running the jobs
without a key while it waits."""
import threading
import time
from concurrent.futures import CancelledError

import pytest

from simkit.lane import Lane, default_threads


def test_jobs_of_one_key_run_one_at_a_time_in_submission_order():
    running, order, overlaps = [0], [], []
    lock = threading.Lock()

    def job(i):
        with lock:
            running[0] += 1
            overlaps.append(running[0])
        time.sleep(0.002)
        with lock:
            order.append(i)
            running[0] -= 1
        return i

    with Lane(3) as lane:
        futures = [lane.submit(job, i, key="truth") for i in range(20)]
        assert [lane.wait(f) for f in futures] == list(range(20))
    assert order == list(range(20)) and max(overlaps) == 1


def test_jobs_without_a_key_run_on_the_waiting_thread_while_the_workers_are_busy():
    release = threading.Event()
    with Lane(1) as lane:
        blocker = lane.submit(release.wait, 5.0, key="truth")  # holds the only worker
        ran_on = [lane.submit(threading.current_thread) for _ in range(3)]
        keyed = lane.submit(lambda: "after", key="truth")
        assert all(lane.wait(f) is threading.current_thread() for f in ran_on)  # stolen by this thread
        release.set()
        assert lane.wait(blocker) is True and lane.wait(keyed) == "after"  # keyed: only on the worker


def test_the_awaited_job_is_run_first_by_the_waiting_thread():
    release = threading.Event()
    ran = []
    with Lane(1) as lane:
        lane.submit(release.wait, 5.0, key="truth")
        earlier = [lane.submit(ran.append, i) for i in range(3)]
        awaited = lane.submit(ran.append, "awaited")
        lane.wait(awaited)
        assert ran == ["awaited"] and not any(f.done() for f in earlier)
        release.set()


def test_a_failing_job_raises_in_the_thread_that_waits_for_it():
    def fail():
        raise ValueError("bad chunk")

    with Lane(2) as lane:
        with pytest.raises(ValueError, match="bad chunk"):
            lane.wait(lane.submit(fail, key="truth"))
        with pytest.raises(ValueError, match="bad chunk"):
            lane.wait(lane.submit(fail))
        assert lane.wait(lane.submit(lambda: 7, key="truth")) == 7  # the key is free again


def test_a_lane_without_workers_runs_each_job_when_it_is_submitted():
    lane = Lane(0)
    future = lane.submit(threading.current_thread)
    assert future.done() and lane.wait(future) is threading.current_thread()
    lane.shutdown()


def test_leaving_on_an_error_cancels_the_queued_jobs_and_ends_the_workers():
    release = threading.Event()
    with pytest.raises(RuntimeError):
        with Lane(1) as lane:
            lane.submit(release.wait, 0.2, key="truth")
            queued = lane.submit(lambda: 1, key="truth")
            raise RuntimeError("stop")
    assert queued.cancelled()
    with pytest.raises(CancelledError):
        lane.wait(queued)
    assert not [t for t in threading.enumerate() if t.name.startswith("simkit-lane")]
    with pytest.raises(RuntimeError, match="closed"):
        lane.submit(lambda: 1)


def test_default_threads_reads_the_environment(monkeypatch):
    monkeypatch.setenv("SIMKIT_NUM_THREADS", "3")
    assert default_threads() == 3
    monkeypatch.delenv("SIMKIT_NUM_THREADS")
    assert 1 <= default_threads() <= 4
