#!/usr/bin/env bash
# Installs the Debian packages geods needs, and only those that are missing.
#   scripts/setup.sh           build, tests and demo
#   scripts/setup.sh --fuzz    + clang and its libFuzzer runtime (make fuzz)
#   scripts/setup.sh --bench   + the anchor libraries of bench/compare (make bench)
set -euo pipefail

cd "$(dirname "$0")/.."

packages=(
  cmake ninja-build g++ ccache pkg-config git
  libeigen3-dev libtbb-dev libassimp-dev libstb-dev libnifti2-dev zlib1g-dev
  libgdal-dev  # terrain rasters (GeoTIFF...) and 2D maps (WKT, GeoJSON, shapefiles) (MIT)
  libzip-dev  # zip archives and .sh3f furniture libraries of shape collections (BSD)
  libcli11-dev nlohmann-json3-dev libfmt-dev
  libgtest-dev libbenchmark-dev libgmp-dev libmpfr-dev
  python3 python3-dev python3-numpy python3-pytest pybind11-dev
  python3-scipy  # the oracle of python/tests/test_convex_hull.py (Qhull)
  python3-mesonpy python3-venv  # pip install . (meson-python drives the CMake build; docs/install.md)
  python3-mypy  # python/tests/test_stubs.py checks calls against the type stubs
  python3-dask python3-distributed  # geods.dask: volumes in chunks, collections, terrain tiles (BSD)
)
for arg in "$@"; do
  case "$arg" in
    --fuzz) packages+=(clang libclang-rt-14-dev) ;;
    --bench)
      bench_npm=1
      # The workload generator runs `npm pack`; any npm will do (a NodeSource
      # nodejs ships its own and conflicts with Debian's npm package).
      command -v npm >/dev/null || packages+=(npm)
      if [[ -f bench/compare/anchor-packages.txt ]]; then
        mapfile -t anchors < <(grep -v '^\s*\(#\|$\)' bench/compare/anchor-packages.txt)
        packages+=("${anchors[@]}")
      fi
      ;;
    *) echo "setup.sh: unknown option '$arg' (expected --fuzz or --bench)" >&2; exit 2 ;;
  esac
done

# npm programs of bench/compare (run with node, never linked into geods), from their lock files.
bench_npm_install() {
  [[ "${bench_npm:-0}" == 1 ]] || return 0
  for lock in bench/compare/*/package-lock.json; do
    dir=$(dirname "$lock")
    [[ -d "$dir/node_modules" ]] || npm ci --prefix "$dir" --no-audit --no-fund --loglevel=error
  done
}

missing=()
for p in "${packages[@]}"; do
  if [[ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null)" != "install ok installed" ]]; then
    missing+=("$p")
  fi
done
if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  bench_npm_install
  exit 0
fi

echo "setup: installing ${missing[*]}"
if [[ $(id -u) -eq 0 ]]; then
  as_root=()
elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
  as_root=(sudo -n)
else
  echo "setup: these Debian packages are missing: ${missing[*]}" >&2
  echo "setup: run as root (or with password-less sudo):" >&2
  echo "  apt-get update && apt-get install -y ${missing[*]}" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
bench_npm_install
echo "setup: done"
