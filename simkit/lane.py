"""The threads that share a run's work: :class:`Lane`, worker threads fed in submission order, whose jobs a thread
waiting for a result runs itself.

A run has two kinds of work beside the caller's own (the IMU, the GNSS observables, the HDF5 writes): the truth
blocks, computed ahead, and the compression of the output's chunks. With one pool for each, a 2-core machine ran
four threads and the caller still waited, idle, for the next truth block. In one lane, a thread that waits
(:meth:`Lane.wait`) compresses meanwhile: two threads, both busy to the end (600 s of truth + IMU at 1 kHz: 0.605 ->
0.555 s wall in same-run pairs, docs/benchmarks.md).

Jobs with a ``key`` (the truth, whose generator must advance in order) run only on the workers, one at a time per
key, in submission order; jobs without one (compression) run on whichever thread takes them first.
"""
from __future__ import annotations

import os
import threading
from collections import deque
from concurrent.futures import Future

from .errors import ScenarioError

THREADS_ENV = "SIMKIT_NUM_THREADS"


def default_threads() -> int:
    """Threads sharing a run's work, the calling thread included: ``$SIMKIT_NUM_THREADS`` when set (1: all of it on
    the calling thread), else up to 4, one per core. Campaign runs use 1: there the runs are the parallelism."""
    value = os.environ.get(THREADS_ENV, "").strip()
    if value:
        if not value.isdigit() or int(value) < 1:
            raise ScenarioError(f"${THREADS_ENV}", f"{value!r}; expected a positive integer (threads per run)")
        return int(value)
    return max(1, min(4, os.cpu_count() or 1))


class Lane:
    """``workers`` threads running submitted jobs in order (0: each job runs at once on the submitting thread)."""

    def __init__(self, workers: int):
        self._jobs: deque = deque()            # (future, fn, args, key), oldest first
        self._busy: set = set()                # keys of the jobs running
        self._lock = threading.Lock()
        self._work = threading.Condition(self._lock)   # a job was queued or a key freed: workers look again
        self._ended = threading.Condition(self._lock)  # a job ended: waiters look again
        self._closed = False
        self._threads = [threading.Thread(target=self._serve, name=f"simkit-lane-{i}", daemon=True)
                         for i in range(workers)]
        for thread in self._threads:
            thread.start()

    @property
    def workers(self) -> int:
        return len(self._threads)

    def submit(self, fn, *args, key=None) -> Future:
        """Queue ``fn(*args)``; its future. ``key``: jobs of one key run one after another, on the workers only."""
        future = Future()
        if not self._threads:
            self._run((future, fn, args, None))
            return future
        with self._lock:
            if self._closed:
                raise RuntimeError("submit on a closed lane")
            self._jobs.append((future, fn, args, key))
            self._work.notify()
        return future

    def wait(self, future: Future):
        """The result of ``future``; until it is done, this thread runs queued jobs without a key (the awaited one
        first when it is such a job)."""
        while not future.done():
            with self._lock:
                job = self._take(stealing=True, prefer=future)
                if job is None:
                    if not future.done():
                        self._ended.wait()
                    continue
            self._run(job)
        return future.result()

    def shutdown(self, wait: bool = True, cancel_futures: bool = False) -> None:
        """No more jobs; ``cancel_futures``: drop the queued ones; ``wait``: return when the workers have ended."""
        with self._lock:
            self._closed = True
            if cancel_futures:
                for future, *_ in self._jobs:
                    future.cancel()
                self._jobs.clear()
            self._work.notify_all()
            self._ended.notify_all()
        if wait:
            for thread in self._threads:
                thread.join()

    def __enter__(self) -> "Lane":
        return self

    def __exit__(self, exc_type, exc, tb):
        self.shutdown(wait=True, cancel_futures=exc_type is not None)
        return False

    def _take(self, stealing: bool, prefer: Future | None = None):
        """The oldest job that may start now on this thread, removed from the queue (``prefer``'s own job first
        when it may); None if none. Called with the lock held."""
        chosen, held = None, set(self._busy)
        for job in self._jobs:
            key = job[3]
            if key is None:
                if job[0] is prefer:
                    chosen = job
                    break
                chosen = chosen or job
                if prefer is None:
                    break
            elif not stealing and key not in held:
                chosen = chosen or job
                break
            else:
                held.add(key)  # later jobs of this key wait for this one
        if chosen is not None:
            self._jobs.remove(chosen)
            if chosen[3] is not None:
                self._busy.add(chosen[3])
        return chosen

    def _run(self, job) -> None:
        future, fn, args, key = job
        try:
            if future.set_running_or_notify_cancel():
                try:
                    future.set_result(fn(*args))
                except BaseException as exc:  # handed to whoever waits for the future
                    future.set_exception(exc)
        finally:
            if self._threads:
                with self._lock:
                    self._busy.discard(key)
                    self._ended.notify_all()
                    if key is not None:
                        self._work.notify()

    def _serve(self) -> None:
        while True:
            with self._lock:
                while (job := self._take(stealing=False)) is None:
                    if self._closed and not self._jobs:
                        return
                    self._work.wait()
            self._run(job)
