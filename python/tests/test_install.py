"""The ways to install of docs/install.md, run as written: cmake --install into
a prefix (man page, completion), pip install . into a fresh virtual environment
(meson-python driving the CMake build, here reusing the release build tree
through the meson option cmake_build_dir), then the installed package from
another directory: python3 -m geods --version, import, a call, the stubs."""
import os
import pathlib
import re
import subprocess
import sys

import pytest

import geods
from conftest import REPO


def cmake_build_dir():
    """The CMake build tree of the geods under test (GEODS_BUILD_DIR, else the one it was imported from)."""
    path = pathlib.Path(os.environ.get("GEODS_BUILD_DIR", pathlib.Path(geods.__file__).resolve().parents[2]))
    if not (path / "CMakeCache.txt").exists():
        pytest.fail(f"no CMake build tree at {path}; set GEODS_BUILD_DIR to the one geods was built in")
    return path


def test_python_m_geods_prints_the_cli_version(cli):
    cli_version = subprocess.run([cli, "--version"], capture_output=True, text=True, check=True).stdout
    r = subprocess.run([sys.executable, "-m", "geods", "--version"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stdout == cli_version == f"geods {geods.__version__}\n"


def test_meson_build_has_the_cmake_version():
    cmake_version = next(line for line in (REPO / "CMakeLists.txt").read_text().splitlines()
                         if line.startswith("project(geods")).split("VERSION ")[1].split()[0]
    assert f"version: '{cmake_version}'" in (REPO / "meson.build").read_text()
    assert geods.__version__ == cmake_version


INSTALL_DOC = REPO / "docs" / "install.md"


def doc_blocks(lang):
    return re.findall(r"^```%s\n(.*?)^```$" % lang, INSTALL_DOC.read_text(), re.S | re.M)


def test_install_doc_shows_the_consumer_project():
    (block,) = doc_blocks("cmake")
    assert (REPO / "tests" / "install" / "consumer" / "CMakeLists.txt").read_text().startswith(block)


def test_install_doc_commands(tmp_path, cli):
    """The ```bash blocks of docs/install.md, as written, from the checkout with HOME a scratch folder:
    cmake --install into ~/.local, pip install . into a fresh venv (reusing the CMake build tree
    through PIP_CONFIG_SETTINGS), python3 -m geods --version from elsewhere, man page, completion."""
    build = cmake_build_dir()
    script = "\n".join(doc_blocks("bash")).replace("build/release", str(build))
    assert "pip install --no-build-isolation ." in script and "cmake --install" in script
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env.update(HOME=str(tmp_path), PIP_NO_INDEX="1", PIP_QUIET="1",
               PIP_CONFIG_SETTINGS=f"setup-args=-Dcmake_build_dir={build}",
               PATH=f"{os.path.dirname(sys.executable)}{os.pathsep}{env['PATH']}")  # python3: the one under test
    r = subprocess.run(["bash", "-euo", "pipefail", "-c", script], capture_output=True, text=True, cwd=REPO,
                       env=env, timeout=600)
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-4000:]
    version = subprocess.run([cli, "--version"], capture_output=True, text=True).stdout.strip()
    lines = [line for line in r.stdout.splitlines() if not line.startswith("-- ")]  # less cmake --install's
    assert lines == [version,  # ~/.local/bin/geods --version
                     version,  # python3 -m geods --version in the venv, from /
                     "[[2. 1. 0.]]",  # geods.edt
                     str(tmp_path / ".local" / "share" / "man" / "man1" / "geods.1"),  # man -w
                     "delaunay delaunay3"], r.stdout + r.stderr  # the completion

    venv_python = tmp_path / ".venvs" / "geods" / "bin" / "python3"
    check = """
import importlib.metadata, pathlib, sys
import geods
where = pathlib.Path(geods.__file__).parent
assert where.is_relative_to(sys.prefix) and sys.prefix != sys.base_prefix, (where, sys.prefix)
assert {"__init__.py", "__main__.py", "_geods.pyi", "py.typed"} <= {p.name for p in where.iterdir()}, list(where.iterdir())
assert importlib.metadata.version("geods") == geods.__version__
"""
    r = subprocess.run([venv_python, "-c", check], capture_output=True, text=True, env=env, cwd=tmp_path, timeout=60)
    assert r.returncode == 0, r.stderr
