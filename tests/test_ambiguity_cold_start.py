"""The first ils call right after install (empty numba cache), and the interpreted kernel that answers it.

While numba compiles the ILS kernel in a background thread (4-6 s of CPU here, see simkit/ambiguity/warmup.py),
ils runs the kernel's own source in the interpreter. These tests hold that path to the same authorities as the
compiled one (the published vectors, brute-force enumeration) and time a cold first call in a fresh process.
"""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from simkit import ambiguity as amb
from simkit.ambiguity import search
from studies.ambiguity_problems import random_problem
from simkit.ambiguity.warmup import interpreted

from conftest import DATA, ROOT

VECTORS = json.loads((DATA / "lambda_testvectors.json").read_text())["cases"]
SQ_RTOL = {"sixdim": 1e-8, "large": 1e-8, "amb18": 1e-6}  # as in test_ambiguity_vectors.py, same reasons

# The bound for the cold first call. Interpreted, the n = 12 "large" vector takes ~5 ms here; with the compile
# thread holding the GIL half of the time and three other jobs on two cores, it stays well under 0.1 s. The
# compiled path it replaces took 13-21 s cold (4-9 s once ils stopped compiling the constrained kernels), so 2 s
# is the brief's target and still fails for any first call that waits for the compiler.
COLD_FIRST_CALL_S = 2.0


@pytest.mark.parametrize("name", sorted(VECTORS))
def test_interpreted_kernel_reproduces_the_published_vectors(name):
    c = VECTORS[name]
    e = c["expected"]
    k = len(e["best_k_candidates"])
    kernel = interpreted(search._ils_kernel)
    code, _, _, cands, sq, *_ = kernel(np.array(c["a_float"]), np.array(c["Q"]), k, search.DEFAULT_MAX_NODES)
    assert code == 0
    np.testing.assert_array_equal(cands, e["best_k_candidates"])
    np.testing.assert_allclose(sq, e["best_k_candidates_sqnorm"], rtol=SQ_RTOL.get(name, 1e-9))


def test_interpreted_kernel_equals_brute_force():
    kernel = interpreted(search._ils_kernel)
    rng = np.random.default_rng(17)
    for k in range(100):
        n = 2 + k % 5
        a, Q, _ = random_problem(rng, n, "bad" if k % 2 else "well")
        _, _, _, cands, sq, *_ = kernel(a, Q, 3, search.DEFAULT_MAX_NODES)
        ref_c, ref_sq = amb.enumerate_ils(a, Q, n_cands=3)
        np.testing.assert_allclose(sq, ref_sq, rtol=1e-9)
        for i in range(3):  # equal up to exact ties
            if not np.array_equal(cands[i], ref_c[i]):
                assert np.isclose(ref_sq[i], ref_sq[i - 1] if i else ref_sq[1], rtol=1e-12)


CHILD = r"""
import json, sys, time
import numpy as np
from simkit.ambiguity import ils, constrained, inner
from simkit.ambiguity.warmup import wait_for_jit
c = json.loads(sys.stdin.read())
a, Q = np.array(c["a_float"]), np.array(c["Q"])
t = time.perf_counter()
res = ils(a, Q, n_cands=2)
first = time.perf_counter() - t
wait_for_jit()
again = ils(a, Q, n_cands=2)
compiled = [f.__name__ for f in (constrained._length_batch, constrained._attitude_batch, inner.sphere_fit,
                                 inner.rotation_fit) if f.signatures]
print(json.dumps({"first_s": first, "cands": res.candidates.tolist(), "again": again.candidates.tolist(),
                  "constrained_compiled": compiled}))
"""


@pytest.mark.slow
def test_cold_first_ils_call_is_fast_and_right(tmp_path):
    case = VECTORS["large"]
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"),  # empty: as right after install
               SIMKIT_NO_PREPARED_CACHE="1")  # and no `simkit compile` in this checkout: a real compile
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])
    out = subprocess.run([sys.executable, "-c", CHILD], input=json.dumps(case), env=env, capture_output=True,
                         text=True, timeout=600, check=True)
    got = json.loads(out.stdout.strip().splitlines()[-1])
    expected = case["expected"]["best_k_candidates"][:2]
    assert got["cands"] == expected and got["again"] == expected
    assert got["constrained_compiled"] == []  # a plain ils compiles none of the constrained kernels
    assert got["first_s"] < COLD_FIRST_CALL_S, got["first_s"]




@pytest.mark.slow
def test_warm_cache_ils_is_compiled_from_the_first_call(tmp_path):
    """With numba's cache warm, a new process runs 100 ils calls at n = 40 compiled from the first: the first
    call loads the cache (~0.2 s) in the caller's thread. With the cache loaded in a background thread instead,
    the first call returns while the interpreted twin is in use and the next calls run ~100x slower (measured
    here: 8 s against 8 ms), so both assertions fail."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), SIMKIT_NO_PREPARED_CACHE="1")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])
    run = lambda: json.loads(subprocess.run([sys.executable, str(ROOT / "studies" / "ils_warm.py")], env=env,
                                            capture_output=True, text=True, timeout=600,
                                            check=True).stdout.strip().splitlines()[-1])
    run()  # compiles and fills the cache
    got = run()
    assert got["compiled_after_first_call"], got
    # calls 2..100 against the same 100 problems once compiled, in the same process: within 2x (+ 5 ms for a
    # scheduler hiccup on a loaded machine; the interpreted calls take ~1000x that)
    assert got["calls_2_100_s"] < 2.0 * got["compiled_100_s"] + 0.005, got


def test_in_cache_is_false_for_uncached_kernels():
    from numba import njit, typeof

    from simkit.ambiguity.warmup import in_cache

    f = njit(lambda x: x + 1)  # no cache at all
    assert not in_cache(f, (typeof(1.0),))
    sig = tuple(typeof(v) for v in (np.zeros(3, np.float32), np.eye(3, dtype=np.float32), 2, 10))
    assert not in_cache(search._ils_kernel, sig)  # never compiled for float32


def test_the_attitude_progress_line_names_a_kernel_running_interpreted(capsys):
    """While a background compile runs, the attitude progress bar says which kernel answers interpreted."""
    from numba import njit

    from simkit.ambiguity import warmup
    from simkit.attitude.solvers import _progress

    j = warmup.jit_when_ready(njit(lambda x: x), lambda x: 1, 40)
    j._thread = object()  # a compile under way: started, not finished
    try:
        assert list(_progress([1, 2, 3], True, "attitude (lambda)")) == [1, 2, 3]
        assert "<lambda>: interpreted while numba compiles it" in capsys.readouterr().err
        j._ready.set()  # finished: the note goes
        list(_progress([1, 2], True, "attitude (lambda)"))
        assert "interpreted" not in capsys.readouterr().err
    finally:
        j._ready.set()
        warmup._ALL.remove(j)
