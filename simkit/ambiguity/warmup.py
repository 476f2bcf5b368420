"""The first call after install: run a kernel's own Python source while numba compiles it in the background.

Why: with an empty numba cache, compiling the kernel behind :func:`simkit.ambiguity.ils` (checks, LtDL,
decorrelation, search, back-transform) takes 4-6 s of CPU on the 2-core reference machine; most of it is numba's
type inference and lowering, not LLVM (``NUMBA_OPT=0`` saves ~1 s), so neither fewer signatures nor smaller
kernels bring it near 2 s. The kernels are plain Python that numba compiles, so the very same code can run in the
interpreter: :func:`interpreted` rebuilds a jitted function with every jitted function it calls (through its
globals or closure cells) replaced by its interpreted twin. That takes milliseconds for the problem sizes GNSS
gives (n <= 20: 1-25 ms here), and gives the same numbers (no fastmath, same operations in the same order).

:class:`JitWhenReady` looks in numba's on-disk cache at the first call: when the kernel is there for the call's
types, it loads it in the caller's thread (~0.2 s) and every call runs compiled. Only when a real compilation is
due does it start one in a daemon thread and answer with the interpreted twin until it is done (loading a warm
cache in the background instead left ils interpreted, ~100x slower, for the seconds the thread took to get the
GIL); problems above ``max_interpreted_n`` wait for the compiled kernel instead. :func:`compiling` names the
kernels being compiled, for a progress line. One implementation, two ways to run it.
"""
from __future__ import annotations

import os
import threading
import types

from numba import typeof
from numba.core.dispatcher import Dispatcher


def interpreted(fn, _memo=None):
    """The Python-interpreted twin of a jitted function: same code, jitted callees replaced by their twins."""
    memo = {} if _memo is None else _memo
    if id(fn) in memo:
        return memo[id(fn)]
    py = fn.py_func
    glb = dict(py.__globals__)
    cells = tuple(types.CellType() for _ in py.__code__.co_freevars)
    twin = types.FunctionType(py.__code__, glb, py.__name__, py.__defaults__, cells or None)
    memo[id(fn)] = twin  # before the recursion: kernels may call each other
    for cell, old in zip(cells, py.__closure__ or ()):
        cell.cell_contents = _twin_of(old.cell_contents, memo)
    for name in py.__code__.co_names:
        if name in glb:
            glb[name] = _twin_of(glb[name], memo)
    return twin


def _twin_of(value, memo):
    return interpreted(value, memo) if isinstance(value, Dispatcher) else value


def in_cache(kernel, sig) -> bool:
    """True when numba's on-disk cache holds ``kernel`` compiled for the types ``sig`` and for this source (the
    same index lookup as numba's own cache load, without loading the machine code). False when numba's cache
    layout is not the expected one: the caller then compiles in the background, which is slower but right."""
    try:
        cache = kernel._cache
        key = cache._index_key(sig, kernel.targetctx.codegen())
        return key in cache._cache_file._load_index()
    except (AttributeError, OSError, EOFError, ValueError):
        return False


class JitWhenReady:
    """Call ``kernel`` compiled once numba has it, its interpreted twin until then (see the module docstring).

    Call through ``.call(*args)``: it is the warming-up function until the compiled kernel is ready, then the
    numba dispatcher itself, so that a warm call pays nothing for this class. ``size(*args)`` gives the problem
    size compared with ``max_interpreted_n``.
    """

    def __init__(self, kernel, size, max_interpreted_n):
        self.kernel, self.size, self.max_interpreted_n = kernel, size, max_interpreted_n
        self.call = self._warming_up
        self._twin = None
        self._thread = None
        self._ready = threading.Event()
        self._lock = threading.Lock()

    def _compile(self, sig):
        try:
            self.kernel.compile(sig)
        finally:  # on failure the next call compiles in the caller's thread and raises there
            self.call = self.kernel
            self._ready.set()

    def start(self, *args):
        """Start compiling for the types of ``args`` in a daemon thread (once)."""
        with self._lock:
            if self._thread is None:
                sig = tuple(typeof(a) for a in args)
                self._thread = threading.Thread(target=self._compile, args=(sig,), daemon=True,
                                                name=f"numba-compile-{self.kernel.__name__}")
                self._thread.start()

    def wait(self):
        """Block until the background compilation (if started) has finished."""
        if self._thread is not None:
            self._ready.wait()

    def compiling(self) -> bool:
        """True while the background compilation runs (the interpreted twin answers meanwhile)."""
        return self._thread is not None and not self._ready.is_set()

    def _warming_up(self, *args):
        if self._ready.is_set():
            return self.kernel(*args)
        with self._lock:
            if self._thread is None and not self.kernel.signatures:
                sig = tuple(typeof(a) for a in args)
                if in_cache(self.kernel, sig):  # a cache load, not a compile: done here, compiled from call 1
                    self.kernel.compile(sig)
                    self.call = self.kernel
                    self._ready.set()
                    return self.kernel(*args)
        self.start(*args)
        if self.size(*args) > self.max_interpreted_n:
            self._ready.wait()
            return self.kernel(*args)
        if self._twin is None:
            self._twin = interpreted(self.kernel)
        return self._twin(*args)


_ALL: list[JitWhenReady] = []


def compiling() -> list[str]:
    """Names of the kernels numba is compiling in the background right now (their interpreted twins answer)."""
    return [j.kernel.__name__ for j in _ALL if j.compiling()]


def jit_when_ready(kernel, size, max_interpreted_n) -> JitWhenReady:
    """A :class:`JitWhenReady` for ``kernel``, registered so that a fork waits for its compilation first."""
    j = JitWhenReady(kernel, size, max_interpreted_n)
    _ALL.append(j)
    return j


def wait_for_jit():
    """Block until every background compilation started so far has finished (benchmarks call it first).

    Also runs before every ``os.fork``: a fork while a thread holds numba's compiler lock would leave the child's
    copy of the lock held forever.
    """
    for j in _ALL:
        j.wait()


os.register_at_fork(before=wait_for_jit)
