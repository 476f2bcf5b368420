"""The filter kernel's interface: named tuples (simkit.estimators.loop.Samples, Nav, Tuning, Fixes, DDRows, Outputs)
instead of long positional argument lists and tuples read by index."""
import ast
from pathlib import Path

import numpy as np

from simkit.estimators import loop
from simkit.estimators.filters import _att_arrays, _dd_arrays

PKG = Path(__file__).resolve().parents[1] / "simkit"


def _parameters(fn: ast.FunctionDef) -> int:
    a = fn.args
    names = [x.arg for x in (*a.posonlyargs, *a.args, *a.kwonlyargs)]
    return len(names) - (names[:1] == ["self"])


def test_no_kernel_function_takes_more_than_eight_arguments():
    long = [f"{path.name}:{fn.name} ({_parameters(fn)})" for path in (PKG / "estimators/loop.py",
                                                                     PKG / "estimators/filters.py")
            for fn in ast.walk(ast.parse(path.read_text())) if isinstance(fn, ast.FunctionDef) and _parameters(fn) > 8]
    assert not long, long


def test_the_empty_inputs_are_the_named_tuples_the_kernel_reads():
    t = np.arange(5) * 0.01
    att, dd = _att_arrays(None, t, 1), _dd_arrays(None, t)
    assert isinstance(att, loop.Fixes) and att.k.size == 0 and att.r.shape == (0, 3, 3)
    assert isinstance(dd, loop.DDRows) and dd.k.size == 0 and dd.offsets.tolist() == [0] and dd.gate.size == 0
    out = loop.allocate(4, 15, 2, 3)
    assert isinstance(out, loop.Outputs) and out.cov.shape == (4, 15, 15) and out.att_nis.shape == (2,)
    assert out.dd_nis.shape == (3,) and (out.status == -1).all()
