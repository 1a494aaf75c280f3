"""Every public callable of geods has a docstring, and one that takes or returns
arrays states their shapes (e.g. "(n, 3)") and, for returned arrays, their dtype
(e.g. "float64"). Arrays are what pybind11's signature line calls
numpy.ndarray, or handle (what python/src/arrays.hpp converts)."""
import importlib.util
import re

import pytest

import geods
from conftest import REPO

spec = importlib.util.spec_from_file_location("gen_stubs", REPO / "python" / "gen_stubs.py")
gen_stubs = importlib.util.module_from_spec(spec)
spec.loader.exec_module(gen_stubs)

SHAPE = re.compile(r"\((?:\s*[\w*+-]+\s*,)+(?:\s*[\w*+-]+\s*)?\)")  # (n, 3), (n,), (nz, ny, nx)
DTYPE = re.compile(r"\b(float32|float64|u?int(8|16|32|64)|bool)\b")
ARRAY_PARAM = re.compile(r"(\w+):\s*(numpy\.ndarray|handle)\b")
NOT_ARRAYS = {"direction"}  # handles that are not arrays: Quadtree/Octree.neighbor's 'N' or 0..5


def public_callables():
    module = geods._geods
    for name in sorted(dir(module)):
        value = getattr(module, name)
        if name.startswith("_"):
            continue
        if isinstance(value, type):
            if issubclass(value, BaseException):
                continue
            for attr, member in sorted(vars(value).items()):
                if isinstance(member, staticmethod):
                    yield f"{name}.{attr}", member.__func__.__doc__, value.__doc__
                elif type(member).__name__ == "instancemethod" and (attr == "__init__" or not attr.startswith("_")):
                    yield f"{name}.{attr}", member.__doc__, value.__doc__
        elif callable(value):
            yield name, value.__doc__, ""


CALLABLES = list(public_callables())


def test_there_are_many():
    assert len(CALLABLES) > 200


def test_classes_have_docstrings():
    for name in dir(geods._geods):
        value = getattr(geods._geods, name)
        if isinstance(value, type) and not name.startswith("_") and not issubclass(value, BaseException):
            assert (value.__doc__ or "").strip(), name


@pytest.mark.parametrize("name,doc,class_doc", CALLABLES, ids=[c[0] for c in CALLABLES])
def test_docstring_states_shapes_and_dtypes(name, doc, class_doc):
    for params, returns, text in gen_stubs.signatures(name.split(".")[-1], doc):
        if name.endswith(".__init__"):
            text = text + "\n" + class_doc  # a constructor may be described by its class
        assert text.strip(), f"{name} has no docstring"
        takes_arrays = any(p not in NOT_ARRAYS for p, _ in ARRAY_PARAM.findall(params))
        if takes_arrays or "numpy.ndarray" in returns:
            assert SHAPE.search(text), f"{name}: its docstring states no shape such as (n, 3):\n{text}"
        if "numpy.ndarray" in returns:
            assert DTYPE.search(text), f"{name}: its docstring does not state the dtype it returns:\n{text}"
