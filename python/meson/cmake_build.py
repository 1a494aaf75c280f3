#!/usr/bin/env python3
"""Builds the extension _geods with the project's CMake build, for meson.build.

A build directory that CMake has already configured (e.g. build/release) is
reused as it is: only its target _geods is brought up to date. An empty one is
configured first, for the Python module alone (no tests, CLI or benchmarks),
in Release with Ninja and the Python that runs this script. The extension is
then copied to --output.
"""
import argparse
import os
import pathlib
import shutil
import subprocess
import sys


def run(command):
    print("+", " ".join(map(str, command)), flush=True)
    subprocess.run(list(map(str, command)), check=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cmake", required=True)
    parser.add_argument("--source", required=True, type=pathlib.Path)
    parser.add_argument("--build", required=True, type=pathlib.Path)
    parser.add_argument("--jobs", type=int, default=0)
    parser.add_argument("--output", required=True, type=pathlib.Path)
    args = parser.parse_args()

    build = args.build.resolve()
    os.environ.setdefault("CCACHE_BASEDIR", str(args.source.resolve()))  # share ccache hits with the checkout's builds
    if not (build / "CMakeCache.txt").exists():
        run([args.cmake, "-S", args.source, "-B", build, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
             "-DGEODS_BUILD_TESTS=OFF", "-DGEODS_BUILD_APPS=OFF", "-DGEODS_BUILD_BENCH=OFF",
             f"-DPython_EXECUTABLE={sys.executable}"])
    run([args.cmake, "--build", build, "--target", "_geods"] + (["-j", args.jobs] if args.jobs else []))

    built = sorted((build / "python" / "geods").glob("_geods*" + args.output.suffix))
    name = args.output.name
    match = [p for p in built if p.name == name]
    if not match:
        sys.exit(f"cmake_build.py: {build}/python/geods has no {name} (found: {[p.name for p in built]}); "
                 "was that build directory configured for another Python?")
    shutil.copy2(match[0], args.output)


if __name__ == "__main__":
    main()
