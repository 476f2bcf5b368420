"""The file's one owner (simkit/io/schema.py), signals and stale temporaries, both deflate paths, and the
architecture rules: acyclic imports, h5py only in simkit/io."""
import ast
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

import simkit
from simkit.io import schema

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "simkit"


def test_readme_table_is_the_schema():
    readme = (ROOT / "README.md").read_text()
    assert schema.markdown_table() in readme, "regenerate with: python -m simkit.io.schema"


def test_every_dataset_written_is_declared_with_its_units_and_frame(tmp_path):
    path = simkit.run("quickstart", out=tmp_path / "q.h5", overrides=["scenario.duration_s=3",
                                                                        "imu.output='increments'"])
    with simkit.open(path) as ds:
        names = [n for n, _ in ds.datasets()]
        assert "imu/dtheta" in names and "gnss/obs/B1I/carrier" in names
        for name, arr in ds.datasets():
            spec = schema.field(name)
            assert arr.attrs["units"] == spec.units, name
            assert arr.attrs.get("frame", "") == spec.frame, name
            assert arr.ndim == len(spec.shape), name


def test_writer_refuses_undeclared_paths_and_shapes(tmp_path):
    from simkit.io import Writer

    with pytest.raises(schema.SchemaError, match="not a dataset"):
        with Writer(tmp_path / "x.h5", {}) as w:
            w.append("truth/speed", np.zeros(3))
    with pytest.raises(schema.SchemaError, match="shape"):
        with Writer(tmp_path / "x.h5", {}) as w:
            w.append("truth/pos_ecef", np.zeros((4, 2)))
    assert not list(tmp_path.iterdir())


def test_lazy_arrays_are_numpy_not_h5py(tmp_path):
    path = simkit.run("quickstart", out=tmp_path / "q.h5", overrides=["scenario.duration_s=2"])
    with simkit.open(path) as ds:
        arr = ds["truth/pos_ecef"]
        assert not isinstance(arr, h5py.Dataset) and arr.shape == (201, 3)
        assert isinstance(arr[10:20], np.ndarray) and np.asarray(arr).shape == (201, 3)
        ids = ds["gnss/sat_id"][:]
        assert ids.dtype.kind == "U" and ids[0][0] in "GC" and len(ids[0]) == 3


@pytest.mark.slow
@pytest.mark.parametrize("hide_isal", [False, True])
def test_both_deflate_paths_decode_through_hdf5(tmp_path, hide_isal):
    """ISA-L when installed, the standard library's zlib otherwise: HDF5's own filter decodes both."""
    code = (
        "import sys\n"
        + ("sys.modules['isal'] = None\n" if hide_isal else "")
        + "import simkit, h5py, numpy as np\n"
        "from simkit.io import shuffle_deflate\n"
        "print(shuffle_deflate.deflate.__name__)\n"
        f"p = simkit.run('quickstart', out=r'{tmp_path / 'q.h5'}', overrides=['scenario.duration_s=700'])\n"
        "f = h5py.File(p, 'r'); d = f['truth/pos_ecef']\n"
        "assert d.compression == 'gzip' and d.chunks[0] < d.shape[0]\n"
        "print(float(np.abs(d[...]).sum()))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    module, total = out.stdout.split()
    assert module == ("zlib" if hide_isal else "isal.isal_zlib")
    assert float(total) > 0


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_and_sighup_remove_the_temporary_file(tmp_path, sig):
    out = tmp_path / "big.h5"
    proc = subprocess.Popen([sys.executable, "-m", "simkit", "run", "xian_static_bds", "-q", "-o", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    deadline = time.time() + 60
    while not list(tmp_path.glob(".big.h5.tmp-*")) and time.time() < deadline:
        time.sleep(0.05)
    time.sleep(0.5)
    proc.send_signal(sig)
    err = proc.communicate(timeout=60)[1]
    assert proc.returncode == 130 and "interrupted" in err and "Traceback" not in err
    assert not list(tmp_path.iterdir())


def test_a_later_run_removes_temporaries_of_dead_writers(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    stale = tmp_path / f".q.h5.tmp-{int(dead.stdout)}"
    stale.write_bytes(b"\0" * 1000)
    simkit.run("quickstart", out=tmp_path / "q.h5", overrides=["scenario.duration_s=2"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["q.h5"]


def _imports(path: Path, module: str) -> set[str]:
    """simkit modules imported by ``path`` (module-level and inside functions)."""
    tree = ast.parse(path.read_text())
    pkg = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.startswith("simkit")}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = pkg.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([base] if base else []))
            if not base.startswith("simkit"):
                continue
            for a in node.names:
                sub = f"{base}.{a.name}"
                out.add(sub if (PKG.parent / (sub.replace(".", "/") + ".py")).exists()
                        or (PKG.parent / sub.replace(".", "/")).is_dir() else base)
    return out


def _graph() -> dict[str, set[str]]:
    graph = {}
    for path in PKG.rglob("*.py"):
        rel = path.relative_to(PKG.parent).with_suffix("")
        module = ".".join(rel.parts[:-1] if rel.name == "__init__" else rel.parts)
        graph[module] = _imports(path, module)
    return graph


def test_module_import_graph_is_acyclic():
    import graphlib

    graph = _graph()
    order = graphlib.TopologicalSorter({k: v - {k} for k, v in graph.items()})
    order.prepare()  # raises CycleError naming the cycle


def test_package_import_graph_is_acyclic():
    """Between sub-packages (trajectory, imu, constellation, gnss, io, scenario, commands, ...) the imports run
    one way; the root package (the public API) is left out."""
    import graphlib

    def package(module):
        parts = module.split(".")
        return parts[1] if len(parts) > 1 else None

    deps: dict[str, set[str]] = {}
    for module, imported in _graph().items():
        src = package(module)
        if src is None:
            continue
        deps.setdefault(src, set()).update(p for p in map(package, imported) if p not in (None, src))
    graphlib.TopologicalSorter(deps).prepare()


# The declared layers, lowest first: a module imports only from layers below its own (and its own package).
# Derived from the code: io needs no stage, validation (observability) needs only the geometry below it and is
# used by attitude (ATDOP), ambiguity needs nothing but errors.
LAYERS = [
    {"errors", "version", "atomic", "rng", "gpstime", "processes", "earth", "solution", "quat", "jitcache", "heap"},
    {"frames", "section", "params", "lane"},
    {"trajectory", "imu", "constellation", "environment"},
    {"gnss"},
    {"io"},
    {"logs"},
    {"scenario"},
    {"pipeline"},
    {"validation"},
    {"ambiguity"},
    {"attitude"},
    {"estimators"},
    {"referee"},
    {"export", "realdata"},
    {"plots"},
    {"campaign"},
    {"api"},
    {"commands"},
    {"cli"},
    {"__main__"},
]
# third-party packages only these sub-packages may import (None: none of simkit): the wheel runs without them
CONFINED = {"pyins": None, "pandas": None, "matplotlib": "plots", "dask": "campaign", "distributed": "campaign",
            "rosbags": "export"}


def _package_edges():
    """{(importing package, imported package): an example module} over every simkit import between packages
    (the root package, the public API, left out)."""
    def package(module):
        parts = module.split(".")
        return parts[1] if len(parts) > 1 else None

    edges = {}
    for module, imported in _graph().items():
        src = package(module)
        for dst in map(package, imported):
            if None not in (src, dst) and dst != src:
                edges.setdefault((src, dst), f"{module} imports simkit.{dst}")
    return edges


def test_every_import_goes_down_the_declared_layers():
    rank = {name: i for i, layer in enumerate(LAYERS) for name in layer}
    edges = _package_edges()
    undeclared = {p for edge in edges for p in edge} - rank.keys()
    assert not undeclared, f"place these in LAYERS: {sorted(undeclared)}"
    upward = [why for (src, dst), why in edges.items() if rank[dst] >= rank[src]]
    assert not upward, "\n".join(sorted(upward))


def test_ambiguity_depends_on_nothing_but_errors():
    assert {dst for src, dst in _package_edges() if src == "ambiguity"} <= {"errors"}


def test_optional_and_lab_dependencies_stay_in_their_sub_package():
    offenders = []
    for path in PKG.rglob("*.py"):
        sub = path.relative_to(PKG).parts[0]
        for name in {n.split(".")[0] for n in _all_imports(path)} & CONFINED.keys():
            if CONFINED[name] != sub:
                offenders.append(f"{path.relative_to(ROOT)} imports {name}")
    assert not offenders, "\n".join(sorted(offenders))


def test_only_simkit_io_imports_h5py():
    offenders = [str(p.relative_to(ROOT)) for p in PKG.rglob("*.py")
                 if "h5py" in {n.split(".")[0] for n in _all_imports(p)} and p.parent.name != "io"]
    assert not offenders


def _all_imports(path):
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
            yield node.module


def test_no_function_over_60_lines():
    long = []
    for path in PKG.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > 60:
                    long.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name} ({n} lines)")
    assert not long, "\n".join(long)


def test_solutions_round_trip_and_replace_only_their_group(tmp_path):
    from simkit.io import read_solution, solution_names, write_solution
    from simkit.solution import Solution

    path = simkit.run("quickstart", out=tmp_path / "q.h5", overrides=["scenario.duration_s=2"])
    with simkit.open(path) as ds:
        t, pos = ds["truth/t"][::10], ds["truth/pos_ecef"][::10]
    k = t.size
    sol = Solution(t=t, pos_ecef=pos, vel_enu=np.zeros((k, 3)), cov=np.tile(np.eye(2), (k, 1, 1)),
                   state_names=("a", "b"), extras={"gamma": np.ones(k), "fixed": np.zeros((k, 4), dtype=np.int64)},
                   extra_units={"gamma": "1"}, config={"filter": "test", "q": [1, 2]})
    write_solution(path, "kf", sol)
    write_solution(path, "other", sol)
    write_solution(path, "kf", Solution(t=t[:3], pos_ecef=pos[:3] + 1.0))   # replaces only "kf"
    assert solution_names(path) == ["kf", "other"]
    back = read_solution(path, "other")
    assert back.state_names == ("a", "b") and back.config == {"filter": "test", "q": [1, 2]}
    np.testing.assert_array_equal(back.pos_ecef, pos)
    np.testing.assert_array_equal(back.extras["fixed"], np.zeros((k, 4)))
    assert back.extra_units["gamma"] == "1" and back.vel_enu.shape == (k, 3)
    kf = read_solution(path, "kf")
    assert kf.t.size == 3 and kf.vel_enu is None and not kf.extras
    with simkit.open(path) as ds:
        assert ds["solutions/kf/pos_ecef"].attrs["frame"] == "ECEF"
        np.testing.assert_array_equal(ds["truth/pos_ecef"][::10], pos)   # the rest of the file untouched
    with pytest.raises(ValueError, match="expected shape"):
        Solution(t=t, pos_ecef=pos[:, :2])
    from simkit.errors import DataFileError

    with pytest.raises(DataFileError, match="no solution 'nope'"):
        read_solution(path, "nope")
