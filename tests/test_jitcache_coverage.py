"""The prepared cache (`simkit compile`, what `pip install .` builds into the wheel) holds every kernel a first
`simkit run` of a bundled scenario and a first `simkit validate` need: with it and an empty numba cache, numba
compiles nothing. Before, the ray tracer of an [environment] and the validation's inversion count were missing:
the first `simkit run urban_canyon` sat 5-6 s at 0 % of its bar while numba compiled (README: "about 1 s")."""
import hashlib
import os
import shutil
import subprocess
import sys

import pytest

from conftest import ROOT


def _digests(folder):
    """{file name: set of SHA-256} of the numba cache files under ``folder``."""
    out = {}
    for f in folder.rglob("*.nb[ic]"):
        out.setdefault(f.name, set()).add(hashlib.sha256(f.read_bytes()).hexdigest())
    return out


@pytest.mark.slow   # `simkit compile` of a copy of the package: about 2 min of CPU
def test_first_urban_run_and_validate_load_every_kernel_from_the_prepared_cache(tmp_path):
    site = tmp_path / "site"
    shutil.copytree(ROOT / "simkit", site / "simkit", ignore=shutil.ignore_patterns("__pycache__", "_jit"))
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "SIMKIT_NO_PREPARED_CACHE")}
    env["PYTHONPATH"] = str(site)
    done = subprocess.run([sys.executable, "-m", "simkit", "compile", "-q"], env=env, cwd=tmp_path,
                          capture_output=True, text=True, timeout=1200)
    assert done.returncode == 0, done.stderr
    prepared = _digests(site / "simkit" / "_jit")

    cache = tmp_path / "numba"   # a new user's empty cache: filled from the prepared one, or by compiling
    env["NUMBA_CACHE_DIR"] = str(cache)
    for args in (["run", "urban_canyon", "-o", "u.h5", "-q", "--set", "scenario.duration_s=5"],
                 ["validate", "u.h5", "--json", "v.json"]):
        step = subprocess.run([sys.executable, "-m", "simkit", *args], env=env, cwd=tmp_path, capture_output=True,
                              text=True, timeout=600)
        assert step.returncode == 0, step.stderr
    compiled = {name for name, digests in _digests(cache).items() if not digests <= prepared.get(name, set())}
    assert not compiled, f"compiled on first use, not in the prepared cache: {sorted(compiled)}"
