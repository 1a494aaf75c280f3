"""Every ```python and ```sh example of README.md and docs/*.md runs cleanly.

The examples run in a scratch folder that holds a link to data/, with the
geods CLI on PATH and the geods package importable. (The ```cpp examples are
compiled and run by the install test of ctest.)
"""
import os
import re
import subprocess
import sys

import pytest

from conftest import REPO

DOCS = [REPO / "README.md"] + sorted((REPO / "docs").glob("*.md"))


def blocks(lang):
    for doc in DOCS:
        if not doc.exists():
            continue
        found = re.findall(r"^```%s\n(.*?)^```$" % lang, doc.read_text(), re.S | re.M)
        for n, code in enumerate(found, 1):
            yield pytest.param(code, id=f"{doc.name}#{n}")


def environment(cli):
    env = dict(os.environ)
    # python3 in a shell example is the Python under test.
    env["PATH"] = f"{cli.parent}{os.pathsep}{os.path.dirname(sys.executable)}{os.pathsep}{env['PATH']}"
    python_dir = os.path.dirname(os.path.dirname(__import__("geods").__file__))
    env["PYTHONPATH"] = python_dir + os.pathsep + env.get("PYTHONPATH", "")
    return env


@pytest.mark.parametrize("code", list(blocks("python")))
def test_python_example(code, cli, workdir):
    result = subprocess.run([sys.executable, "-c", code], cwd=workdir, env=environment(cli),
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.parametrize("code", list(blocks("sh")))
def test_shell_example(code, cli, workdir):
    result = subprocess.run(["bash", "-euo", "pipefail", "-c", code], cwd=workdir, env=environment(cli),
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
