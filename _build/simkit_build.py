"""simkit's build backend: setuptools', plus the prepared numba cache compiled into the wheel (docs/cold_start.md).

``pip install .`` builds a wheel and installs it. Before setuptools packs the wheel, this backend runs
``simkit compile`` on the sources being built (with the build environment's numba and numpy, which pip installs
there: :func:`get_requires_for_build_wheel` adds simkit's own dependencies), so the installed package carries
``simkit/_jit`` and the first ``simkit run`` / ``simkit solve`` loads its kernels instead of compiling them. A cache
that does not fit the installed numba, numpy or CPU is never loaded (simkit/jitcache.py), only unused. When the
compile fails or ``SIMKIT_BUILD_COMPILE=0`` is set, the wheel is built without it (numba compiles on first use,
as before). Editable installs and sdists are setuptools' own.
"""
from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from pathlib import Path

from setuptools import build_meta as _setuptools
from setuptools.build_meta import (  # noqa: F401 - the PEP 517/660 hooks setuptools answers alone
    build_editable, build_sdist, get_requires_for_build_editable, get_requires_for_build_sdist,
    prepare_metadata_for_build_editable, prepare_metadata_for_build_wheel)

ROOT = Path(__file__).resolve().parents[1]


def get_requires_for_build_wheel(config_settings=None):
    """setuptools' requirements and simkit's dependencies: the compile imports simkit."""
    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    return _setuptools.get_requires_for_build_wheel(config_settings) + list(deps)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    if os.environ.get("SIMKIT_BUILD_COMPILE", "1") != "0":
        print("simkit: compiling the numba kernels into the wheel (simkit compile, a few minutes of CPU; "
              "SIMKIT_BUILD_COMPILE=0 skips it)", file=sys.stderr, flush=True)
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
        env.pop("NUMBA_CACHE_DIR", None)
        done = subprocess.run([sys.executable, "-m", "simkit", "compile", "-q"], cwd=ROOT, env=env)
        if done.returncode:
            print(f"simkit: the compile failed (exit code {done.returncode}); the wheel is built without the "
                  "prepared cache", file=sys.stderr, flush=True)
    return _setuptools.build_wheel(wheel_directory, config_settings, metadata_directory)
