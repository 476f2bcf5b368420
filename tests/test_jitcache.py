"""A read-only install (a container, a cluster image) caches the compiled kernels instead of compiling them in
every process (simkit/jitcache.py). The install is a copy of the package whose directories cannot be written:
mode a-w, and a file named ``__pycache__`` in each directory (mode bits do not stop root, a file in the way does).
A prepared cache (``simkit compile``) in the install seeds whichever cache directory numba uses."""
import importlib.util
import json
import os
import pickle
import shutil
import stat
import subprocess
import sys

import numpy as np
import pytest

from simkit import jitcache

from conftest import ROOT

# a small cached kernel (~0.5 s to compile): the child reports whether it came from numba's cache
CHILD = r"""
import json, numpy as np
from simkit.estimators import kalman
kalman._chol(np.eye(3))
st = kalman._chol.stats
print(json.dumps({"path": st.cache_path, "hits": sum(st.cache_hits.values()),
                  "misses": sum(st.cache_misses.values())}))
"""


@pytest.fixture
def read_only_install(tmp_path):
    site = tmp_path / "site"
    shutil.copytree(ROOT / "simkit", site / "simkit", ignore=shutil.ignore_patterns("__pycache__", "_jit"))
    dirs = [d for d in (site / "simkit").rglob("*") if d.is_dir()] + [site / "simkit"]
    for d in dirs:
        (d / "__pycache__").touch()
    for p in dirs + [f for f in site.rglob("*") if f.is_file()]:
        p.chmod(p.stat().st_mode & ~(stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH))
    yield site
    for p in site.rglob("*"):
        p.chmod(p.stat().st_mode | stat.S_IWUSR)


def _child(site, **env):
    full = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    full.update(PYTHONPATH=str(site), **env)
    out = subprocess.run([sys.executable, "-c", CHILD], env=full, capture_output=True, text=True, timeout=300,
                         cwd=site.parent)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_read_only_install_uses_the_user_cache(read_only_install, tmp_path):
    user = tmp_path / "user-cache"
    first = _child(read_only_install, XDG_CACHE_HOME=str(user), TMPDIR=str(tmp_path))
    again = _child(read_only_install, XDG_CACHE_HOME=str(user), TMPDIR=str(tmp_path))
    assert first["path"].startswith(str(user / "numba")) and first["misses"] == 1
    assert again == {**first, "hits": 1, "misses": 0}  # the second process loads, it does not compile


def test_read_only_install_and_home_fall_back_to_a_temporary_cache(read_only_install, tmp_path):
    """Without the fallback numba refuses every cached kernel at import: simkit could not be imported at all."""
    blocked = tmp_path / "no-cache-here"
    blocked.touch()  # a file: no cache directory can be made below it
    temp = tmp_path / "tmp"
    temp.mkdir()
    env = dict(XDG_CACHE_HOME=str(blocked), TMPDIR=str(temp))
    first, again = _child(read_only_install, **env), _child(read_only_install, **env)
    assert first["path"].startswith(str(temp / f"simkit-numba-{os.getuid()}")) and first["misses"] == 1
    assert again == {**first, "hits": 1, "misses": 0}


def test_a_set_numba_cache_dir_is_left_alone(monkeypatch, tmp_path):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    assert jitcache.choose() is None
    assert os.environ["NUMBA_CACHE_DIR"] == str(tmp_path)


def test_writable_is_false_below_a_file(tmp_path):
    (tmp_path / "f").touch()
    assert jitcache.writable(tmp_path / "d")
    assert not jitcache.writable(tmp_path / "f" / "d")


# The prepared cache (`simkit compile`, simkit/_jit): compile the kernel once into a scratch cache, then place its
# files where `simkit compile` puts them, in the read-only copy
def _prepare(site, tmp_path):
    scratch = tmp_path / "scratch"
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(PYTHONPATH=str(ROOT), NUMBA_CACHE_DIR=str(scratch))
    out = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    files = sorted(scratch.rglob("kalman._chol-*.nb[ic]"))
    assert [f.suffix for f in files] == [".nbc", ".nbi"]
    package = site / "simkit"
    prepared = package / "_jit" / "estimators"
    package.chmod(0o755)
    prepared.mkdir(parents=True)
    for f in files:
        shutil.copyfile(f, prepared / f.name)
    (package / "_jit" / "SOURCES").write_text(jitcache.sources_digest(package))  # as `simkit compile` does
    for p in [package, prepared.parent, prepared, *prepared.iterdir()]:  # read-only again, as in an image
        p.chmod(p.stat().st_mode & ~(stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH))
    return prepared


def test_a_prepared_cache_seeds_an_empty_numba_cache_dir(read_only_install, tmp_path):
    """Compiled in another directory tree (another path, other mtimes): loaded, not compiled."""
    _prepare(read_only_install, tmp_path)
    empty = tmp_path / "empty"
    got = _child(read_only_install, NUMBA_CACHE_DIR=str(empty))
    assert got["path"].startswith(str(empty)) and got == {**got, "hits": 1, "misses": 0}


def test_a_prepared_cache_serves_a_read_only_install(read_only_install, tmp_path):
    _prepare(read_only_install, tmp_path)
    got = _child(read_only_install, XDG_CACHE_HOME=str(tmp_path / "user-cache"), TMPDIR=str(tmp_path))
    assert got["path"].startswith(str(tmp_path / "user-cache" / "numba"))
    assert got["hits"] == 1 and got["misses"] == 0


def test_a_prepared_cache_of_other_sources_does_not_seed(read_only_install, tmp_path):
    """A callee's source changed (kalman._chol compiles into its callers from another file): numba's stamp of
    the caller's own file would still match, so the prepared cache as a whole is left aside."""
    _prepare(read_only_install, tmp_path)
    (read_only_install / "simkit" / "_jit" / "SOURCES").chmod(0o644)
    (read_only_install / "simkit" / "_jit" / "SOURCES").write_text("0" * 64)
    got = _child(read_only_install, NUMBA_CACHE_DIR=str(tmp_path / "empty"))
    assert got["hits"] == 0 and got["misses"] == 1


def test_a_prepared_cache_of_another_numpy_is_not_loaded(read_only_install, tmp_path):
    """numba's index records its own version, not numpy's: the stamp carries numpy's version."""
    prepared = _prepare(read_only_install, tmp_path)
    index = next(prepared.glob("*.nbi"))
    index.chmod(0o644)
    with open(index, "rb") as f:
        version = pickle.load(f)
        (source, numpy_version), overloads = pickle.loads(f.read())
    assert numpy_version == np.__version__
    with open(index, "wb") as f:
        pickle.dump(version, f)
        f.write(pickle.dumps(((source, "1.0.0"), overloads)))
    got = _child(read_only_install, NUMBA_CACHE_DIR=str(tmp_path / "empty"))
    assert got["hits"] == 0 and got["misses"] == 1


def test_only_simkit_sources_get_the_prepared_locator(tmp_path):
    from numba.core.caching import FunctionCache

    import numba

    other = tmp_path / "other_module.py"
    other.write_text("def f(x):\n    return x + 1\n")
    spec = importlib.util.spec_from_file_location("other_module", other)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    from simkit.estimators import kalman

    assert type(FunctionCache(kalman._chol.py_func)._impl.locator) is jitcache.register()
    assert type(FunctionCache(mod.f)._impl.locator) is not jitcache.register()
    assert numba.njit(mod.f)(1) == 2


def test_seed_copies_only_into_a_cache_without_the_kernel(tmp_path):
    prepared, cache = tmp_path / "p", tmp_path / "c"
    prepared.mkdir()
    cache.mkdir()
    for name in ("m.f-3.py311.nbi", "m.f-3.py311.1.nbc", "m.f-30.py311.nbi", "m.g-3.py311.nbi"):
        (prepared / name).write_text(name)
    assert jitcache.seed(str(prepared), str(cache), "m.f-3.py311") == 2
    assert sorted(p.name for p in cache.iterdir()) == ["m.f-3.py311.1.nbc", "m.f-3.py311.nbi"]
    (cache / "m.f-3.py311.nbi").write_text("newer")
    assert jitcache.seed(str(prepared), str(cache), "m.f-3.py311") == 0  # numba's own index is never replaced
    assert (cache / "m.f-3.py311.nbi").read_text() == "newer"


def test_compile_into_an_install_it_cannot_write_is_one_line_exit_2(monkeypatch, tmp_path, capsys):
    from simkit.cli import main

    blocked = tmp_path / "site-packages"
    blocked.touch()  # a file: nothing can be written below it
    monkeypatch.setattr(jitcache, "PREPARED", blocked / "simkit" / "_jit")
    assert main(["compile", "-q"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(blocked / "simkit" / "_jit") in err[0] and "simkit compile" in err[0]


def test_import_simkit_leaves_numba_unimported_and_its_kernels_still_get_the_locator():
    """``import simkit`` must not import numba (a truth + IMU run never needs it); the prepared-cache locator is
    registered as numba's package finishes loading, before any simkit kernel is defined."""
    code = ("import sys, simkit; assert 'numba' not in sys.modules; "
            "from simkit.estimators import loop; from simkit import jitcache; "
            "print(type(loop.run._cache._impl.locator) is jitcache.PreparedLocator)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "True"
