"""Where numba caches simkit's compiled kernels, so that a read-only install does not compile in every process.

numba looks for a cache directory per source file: ``$NUMBA_CACHE_DIR`` when set, else ``__pycache__`` next to
the source when writable, else the user's cache directory (``$XDG_CACHE_HOME/numba``, ``~/.cache/numba``). In a
container or a cluster image both of the last two can be read-only; numba then refuses every ``cache=True``
function at import ("no locator available"), and simkit could not even be imported. :func:`choose` runs once,
when numba is imported (``import simkit`` arranges it), before any kernel is defined: with ``$NUMBA_CACHE_DIR``
unset and neither directory writable, it points numba at ``<temporary directory>/simkit-numba-<uid>`` (also
exported, so that worker processes started from this one share it). Compiled code is keyed by source, CPU and
numba version, so a shared directory is safe.

A prepared cache (docs/cold_start.md): ``simkit compile`` runs the kernels a first run needs once and stores
what numba compiled in ``simkit/_jit`` (a tree mirroring the package's). :func:`register` (also when numba
loads) puts :class:`PreparedLocator` first in numba's list of cache locators, for simkit's own source files
only: it keeps numba's choice of directory, and when that directory has no index for a kernel yet, copies the
prepared files there first (an empty ``$NUMBA_CACHE_DIR``, a read-only install, a new user: numba then loads
instead of compiling). The source stamp is the SHA-256 of the source file and numpy's version: a prepared
cache survives a reinstall or a copy (new mtimes). The prepared cache seeds only while the package's sources
are those it was built from (:func:`sources_digest`, stored in ``_jit/SOURCES``); a cache from another source,
numpy or numba version
(numba's index records its version) or another CPU (numba's index key) is never loaded, only replaced.
``SIMKIT_NO_PREPARED_CACHE=1`` turns the seeding off (what a first run costs without a prepared cache).
"""
from __future__ import annotations

import functools
import os
import sys
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent
PREPARED = _PACKAGE / "_jit"  # the prepared cache, filled by `simkit compile` (simkit/commands/compile.py)


def writable(directory: Path) -> bool:
    """True when a file can be created in ``directory`` (created if missing), the test numba itself applies."""
    import tempfile

    try:
        directory.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=directory):
            return True
    except OSError:
        return False


def user_cache_dir() -> Path:
    """numba's user-wide cache directory on this platform."""
    from numba.misc.appdirs import AppDirs

    return Path(AppDirs(appname="numba", appauthor=False).user_cache_dir)


def fallback_dir() -> Path:
    """The cache directory used when numba has none: per user, under the system's temporary directory."""
    import tempfile

    uid = os.getuid() if hasattr(os, "getuid") else os.getlogin()
    return Path(tempfile.gettempdir()) / f"simkit-numba-{uid}"


def choose() -> Path | None:
    """Set numba's cache directory when it would have none (see the module docstring); returns the directory
    set, or None when numba's own choice stands."""
    if os.environ.get("NUMBA_CACHE_DIR") or writable(_PACKAGE / "__pycache__") or writable(user_cache_dir()):
        return None
    path = fallback_dir()
    if not writable(path):
        return None  # nowhere to write: numba then explains at the first kernel it cannot cache
    os.environ["NUMBA_CACHE_DIR"] = str(path)
    if "numba.core.config" in sys.modules:  # numba read its configuration at import: tell it too
        sys.modules["numba.core.config"].CACHE_DIR = str(path)
    return path


def source_stamp(py_file: str) -> tuple[str, str]:
    """The stamp numba stores in a kernel's cache index and compares at load: (SHA-256 of the source file,
    numpy's version). No mtime, no path: a copied or reinstalled package keeps its cache."""
    import hashlib

    import numpy

    with open(py_file, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest(), numpy.__version__


def sources_digest(package: Path = _PACKAGE) -> str:
    """SHA-256 over every ``.py`` file of the package (relative path and contents). ``simkit compile`` stores it
    with the prepared cache, which seeds numba's only while the sources are still these: numba's stamp covers a
    kernel's own file, not the callees compiled into it from other files."""
    import hashlib

    digest = hashlib.sha256()
    for path in sorted(p for p in package.rglob("*.py") if PREPARED.name not in p.relative_to(package).parts):
        digest.update(path.relative_to(package).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()


@functools.lru_cache(maxsize=None)
def prepared_matches(prepared: str) -> bool:
    """True when the prepared cache ``prepared`` was built from this package's sources (its ``SOURCES`` file)."""
    try:
        return Path(prepared, "SOURCES").read_text().strip() == sources_digest(Path(prepared).parent)
    except OSError:
        return False


@functools.lru_cache(maxsize=None)
def _listing(directory: str) -> tuple[str, ...]:
    try:
        return tuple(os.listdir(directory))
    except OSError:
        return ()


def seed(prepared: str, cache: str, base: str) -> int:
    """Copy kernel ``base``'s index (``base.nbi``) and data files (``base.N.nbc``) from the prepared directory
    to numba's ``cache`` directory when ``cache`` has no index for it; returns the number of files copied.
    Each file lands under a temporary name and is renamed into place (data first, index last), so a
    process starting alongside never reads half a file."""
    if prepared == cache or os.path.exists(os.path.join(cache, base + ".nbi")):
        return 0
    names = [n for n in _listing(prepared) if n.startswith(base + ".") and n.endswith(".nbc")]
    if base + ".nbi" not in _listing(prepared):
        return 0
    import shutil
    import tempfile

    copied = 0
    for name in names + [base + ".nbi"]:
        fd, tmp = tempfile.mkstemp(dir=cache, prefix=".seed-")
        try:
            with os.fdopen(fd, "wb") as out, open(os.path.join(prepared, name), "rb") as src:
                shutil.copyfileobj(src, out)
            os.replace(tmp, os.path.join(cache, name))
            copied += 1
        except OSError:
            try:
                os.unlink(tmp)
            except OSError:
                pass
            return copied  # numba compiles what is missing, as without a prepared cache
    return copied


def _numba_locators() -> list:
    """numba's cache-implementation class and its list of locator classes (the name changed in numba 0.6x)."""
    from numba.core import caching

    impl = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl")
    return impl._locator_classes


def _locator_base():
    from numba.core import caching

    return caching._CacheLocator


class _Prepared:
    """The locator of simkit's kernels: numba's own choice of directory (``inner``, the first of numba's locators
    that accepts the file), seeded from the prepared cache, with :func:`source_stamp`. :func:`register` makes
    ``PreparedLocator`` of it and numba's locator base (numba is imported only then)."""

    def __init__(self, inner, py_func, py_file):
        self._inner, self._py_file = inner, py_file
        rel = Path(py_file).resolve().parent.relative_to(_PACKAGE)
        self.prepared = str(PREPARED / rel)
        qualname = getattr(py_func, "__qualname__", py_func.__name__)
        fullname = f"{Path(py_file).stem}.{qualname}".replace("<", "").replace(">", "")
        self.base = (f"{fullname}-{inner.get_disambiguator()}.py{sys.version_info[0]}{sys.version_info[1]}"
                     f"{getattr(sys, 'abiflags', '')}")  # numba's file name of the kernel (CacheImpl)

    def ensure_cache_path(self):
        self._inner.ensure_cache_path()

    def get_cache_path(self):
        return self._inner.get_cache_path()

    def get_source_stamp(self):
        return source_stamp(self._py_file)

    def get_disambiguator(self):
        return self._inner.get_disambiguator()

    @classmethod
    def from_function(cls, py_func, py_file):
        try:
            Path(py_file).resolve().relative_to(_PACKAGE)
        except (ValueError, OSError):
            return None  # not simkit's: numba's own locators decide
        for other in _numba_locators():
            if other is cls:
                continue
            inner = other.from_function(py_func, py_file)
            if inner is not None:
                self = cls(inner, py_func, py_file)
                cache = self.get_cache_path()
                if (not os.environ.get("SIMKIT_NO_PREPARED_CACHE")  # the digest only when there is a gap to fill
                        and not os.path.exists(os.path.join(cache, self.base + ".nbi"))
                        and prepared_matches(str(PREPARED))):
                    seed(self.prepared, cache, self.base)
                return self
        return None


PreparedLocator = None


def register():
    """Put :class:`PreparedLocator` first in numba's locator list (once); returns the class. Call before any
    simkit kernel is defined: numba picks a kernel's locator when the decorator runs."""
    global PreparedLocator
    if PreparedLocator is None:
        PreparedLocator = type("PreparedLocator", (_Prepared, _locator_base()),
                               {"__doc__": _Prepared.__doc__, "__module__": __name__})
    classes = _numba_locators()
    if PreparedLocator not in classes:
        classes.insert(0, PreparedLocator)
    return PreparedLocator


class _RegisterAfterNumba:
    """A ``sys.meta_path`` finder that calls :func:`choose` and :func:`register` right after numba's package has
    been executed, so that ``import simkit`` does not import numba (a truth + IMU run never needs it) and still
    every simkit kernel, defined after numba is imported, gets the locator and a cache directory."""

    def find_spec(self, name, path=None, target=None):
        if name != "numba":
            return None
        import importlib.util

        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(name)
        if spec is not None and spec.loader is not None:
            spec.loader = _ThenRegister(spec.loader)
        return spec


class _ThenRegister:
    """numba's loader, then :func:`choose` (numba's configuration is loaded: it sets ``config.CACHE_DIR`` too)
    and :func:`register`."""

    def __init__(self, loader):
        self._loader = loader

    def create_module(self, spec):
        return self._loader.create_module(spec)

    def exec_module(self, module):
        self._loader.exec_module(module)
        choose()
        register()

    def __getattr__(self, name):
        return getattr(self._loader, name)


def register_when_numba_loads() -> None:
    """:func:`choose` and :func:`register` now when numba is imported already, else right after it is (once): a
    process that never loads numba (a truth + IMU run) neither tests a directory nor imports what it needs."""
    if "numba" in sys.modules:
        choose()
        register()
    elif not any(isinstance(f, _RegisterAfterNumba) for f in sys.meta_path):
        sys.meta_path.insert(0, _RegisterAfterNumba())

