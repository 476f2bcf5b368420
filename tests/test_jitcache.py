"""A read-only install (a container, a cluster image) caches the compiled kernels instead of compiling them in
every process (simkit/jitcache.py). The install is a copy of the package whose directories cannot be written:
mode a-w, and a file named ``__pycache__`` in each directory (mode bits do not stop root, a file in the way does)."""
import json
import os
import shutil
import stat
import subprocess
import sys

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
    shutil.copytree(ROOT / "simkit", site / "simkit", ignore=shutil.ignore_patterns("__pycache__"))
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
