#!/usr/bin/python3
"""Checks what `cmake --install` put under PREFIX besides the library: the CLI,
its man page (every command and option of the CLI's help), its bash completion
(sourced in bash, it completes commands, options and option values) and the
Python package (importable from the prefix, with its type stubs).

Usage: check_installed.py PREFIX
"""
import os
import glob
import re
import shutil
import subprocess
import sys
import tempfile

prefix = sys.argv[1]
cli = os.path.join(prefix, "bin", "geods")
man = os.path.join(prefix, "share", "man", "man1", "geods.1")
completion = os.path.join(prefix, "share", "bash-completion", "completions", "geods")
failures = []


def check(ok, message):
    if not ok:
        failures.append(message)


def run(*command, **kwargs):
    return subprocess.run(command, capture_output=True, text=True, check=True, **kwargs).stdout


for path in (cli, man, completion):
    check(os.path.isfile(path), f"not installed: {path}")
if failures:
    sys.exit("\n".join(failures))

# The man page documents every command of the installed CLI and each one's options.
page = open(man).read().replace("\\-", "-")
commands = re.findall(r"^  (\S+) ", run(cli, "--help").split("Subcommands:")[1], re.M)
check(len(commands) >= 20, f"too few commands in geods --help: {commands}")
for command in commands:
    check(f'.SS "geods {command}"' in page, f"man page: no section for geods {command}")
    for option in re.findall(r"^  (?:-\w,)?(--[\w-]+)", run(cli, command, "--help"), re.M):
        check(f"\\fB{option}\\fR" in page.split(f'.SS "geods {command}"')[1].split(".SS")[0],
              f"man page: geods {command} lacks {option}")
if shutil.which("groff"):
    warnings = subprocess.run(["groff", "-man", "-ww", "-z", man], capture_output=True, text=True).stderr
    check(not warnings.strip(), f"groff warns about the man page: {warnings}")


def complete(*words):
    script = (f"source {completion}; COMP_WORDS=({' '.join(repr(w) for w in words)}); "
              f"COMP_CWORD={len(words) - 1}; _geods; echo \"${{COMPREPLY[@]}}\"")
    return run("bash", "-c", script).split()


check("delaunay3" in complete("geods", "del"), f"completion of 'geods del': {complete('geods', 'del')}")
check(sorted(complete("geods", "")) == sorted(commands), "completion of 'geods ': not the commands of --help")
check(complete("geods", "delaunay3", "--nei") == ["--neighbors"], "completion of 'geods delaunay3 --nei'")
check(complete("geods", "shapes", "") == ["index", "query", "evaluate"], "completion of 'geods shapes '")
check("pseudonormal" in complete("geods", "sdf", "--sign", ""), "completion of 'geods sdf --sign '")
check("--output" in complete("geods", "shapes", "index", "--o"), "completion of 'geods shapes index --o'")

# The Python package, from the prefix, in another directory.
packages = glob.glob(os.path.join(prefix, "lib*", "python3*", "*-packages", "geods", "__init__.py"))
if len(packages) != 1:
    sys.exit(f"check_installed.py: expected one Python package geods under {prefix}, found {packages}")
package = os.path.dirname(os.path.dirname(packages[0]))
for name in ("__init__.py", "__main__.py", "_geods.pyi", "py.typed"):
    check(os.path.isfile(os.path.join(package, "geods", name)), f"not installed: {package}/geods/{name}")
env = dict(os.environ, PYTHONPATH=package)
with tempfile.TemporaryDirectory() as elsewhere:
    version = run(sys.executable, "-m", "geods", "--version", env=env, cwd=elsewhere).strip()
    check(version == run(cli, "--version").strip(), f"python3 -m geods --version: {version!r}")
    where = run(sys.executable, "-c", "import geods; print(geods.__file__)", env=env, cwd=elsewhere).strip()
    check(where.startswith(os.path.realpath(package)) or where.startswith(package), f"geods imported from {where}")

if failures:
    sys.exit("check_installed.py:\n  " + "\n  ".join(failures))
print(f"check_installed.py: CLI, man page ({len(commands)} commands), bash completion and Python package ok")
