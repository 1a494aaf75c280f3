"""The type stubs python/geods/_geods.pyi: exactly what python/gen_stubs.py
generates from the built module (so they cannot drift), and mypy checks geods
calls with them: a correct script passes, wrong calls are reported."""
import os
import pathlib
import subprocess
import sys

import geods
from conftest import REPO

PACKAGE_DIR = pathlib.Path(geods.__file__).resolve().parent


def test_stubs_are_those_of_the_built_module(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(PACKAGE_DIR.parent))
    r = subprocess.run([sys.executable, REPO / "python" / "gen_stubs.py", "--output", tmp_path / "_geods.pyi"],
                       capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0, r.stderr
    generated = (tmp_path / "_geods.pyi").read_text()
    committed = (REPO / "python" / "geods" / "_geods.pyi").read_text()
    assert generated == committed, (
        "python/geods/_geods.pyi is not what the module generates: run "
        "PYTHONPATH=build/release/python /usr/bin/python3 python/gen_stubs.py")
    assert (PACKAGE_DIR / "_geods.pyi").read_text() == committed  # the build tree's copy
    assert (PACKAGE_DIR / "py.typed").exists()
    # Every public name of the module has a stub.
    names = {n for n in dir(geods._geods) if not n.startswith("_")}
    for name in names:
        assert f"\nclass {name}" in committed or f"\ndef {name}(" in committed or f"\n{name}: " in committed, name


GOOD = """
import numpy as np
import numpy.typing as npt
import geods

points = np.random.default_rng(1).random((100, 3))
tree = geods.KdTree(points, leaf_size=4)
n: int = len(tree)
idx: npt.NDArray[np.int64] = tree.query_box([0, 0, 0], [0.5, 0.5, 0.5])
dist: npt.NDArray[np.float64] = geods.edt(np.ones((4, 4)))
V = np.zeros((3, 3), dtype=np.float32)
bvh = geods.TriangleBvh(V, np.array([[0, 1, 2]]), builder="sah", leaf_size=4)
hit: npt.NDArray[np.bool_] = bvh.occluded(V, V)
version: str = geods.__version__.upper()
"""

BAD = """
import numpy as np
import geods

tree = geods.KdTree(np.zeros((4, 3)))
tree.no_such_method()
geods.no_such_function()
geods.TriangleBvh(np.zeros((3, 3)), np.zeros((1, 3)), leaf_size="eight")
text: str = geods.TriangleBvh(np.zeros((3, 3)), np.array([[0, 1, 2]])).occluded(np.zeros((1, 3)), np.ones((1, 3)))
"""


def test_mypy_checks_geods_calls(tmp_path):
    (tmp_path / "good.py").write_text(GOOD)
    (tmp_path / "bad.py").write_text(BAD)
    env = dict(os.environ, MYPYPATH=str(PACKAGE_DIR.parent))
    r = subprocess.run([sys.executable, "-m", "mypy", "--strict", "--no-error-summary",
                        "--cache-dir", str(tmp_path / "cache"), "good.py", "bad.py"],
                       capture_output=True, text=True, cwd=tmp_path, env=env, timeout=300)
    errors = [line for line in r.stdout.splitlines() if ": error:" in line]
    assert r.returncode == 1 and len(errors) == 4, r.stdout + r.stderr  # good.py has none
    assert [line.split(":")[:2] for line in errors] == [["bad.py", "6"], ["bad.py", "7"], ["bad.py", "8"],
                                                         ["bad.py", "9"]], r.stdout
    assert "no_such_method" in errors[0] and "no_such_function" in errors[1]
    assert '"leaf_size"' in errors[2] and 'expected "int"' in errors[2]
    assert "ndarray" in errors[3] and '"str"' in errors[3]
