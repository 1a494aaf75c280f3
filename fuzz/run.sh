#!/usr/bin/env bash
# Runs every libFuzzer target for SECONDS each, with a corpus seeded from the
# files in data/ and small generated seeds (make_seeds.py). Fails if any target
# crashes, leaks, times out or trips a sanitizer; the reproducers are kept.
#   fuzz/run.sh BUILD_DIR SECONDS
set -euo pipefail
build=${1:?usage: fuzz/run.sh BUILD_DIR SECONDS}
seconds=${2:-60}
root=$(cd "$(dirname "$0")/.." && pwd)
bin=$build/bin
work=$(mktemp -d "${TMPDIR:-/tmp}/geods_fuzz.XXXXXX")
artifacts=$build/fuzz-artifacts
mkdir -p "$artifacts"

python3 "$root/fuzz/make_seeds.py" "$work"
prefixed() {  # copies a data file into a selector-byte target's corpus
  local target=$1 byte=$2 file=$3
  [ -f "$root/data/$file" ] && { printf "\\x$byte"; cat "$root/data/$file"; } > "$work/$target/$file" || true
}
copy() { [ -f "$root/data/$2" ] && cp "$root/data/$2" "$work/$1/" || true; }
copy ply bunny.ply
copy obj teapot.obj
copy image brick.png
copy nifti t1_head.nii.gz
for f in jacksboro_dem.npy land_points.npy land_segments.npy; do copy npy "$f"; done
prefixed points 00 land_points.npy
prefixed segments 00 land_segments.npy

# A small ASan quarantine: Assimp's large transient allocations would otherwise
# count against libFuzzer's RSS limit.
export ASAN_OPTIONS=${ASAN_OPTIONS:-quarantine_size_mb=64:detect_leaks=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$root/fuzz/lsan.supp:print_suppressions=0}

failed=()
for target in ply obj stl off gltf image npy nrrd nifti points segments archive shape; do
  exe=$bin/fuzz_$target
  if [ ! -x "$exe" ]; then
    echo "missing $exe (build the fuzz preset first)" >&2
    failed+=("$target(missing)")
    continue
  fi
  log=$work/$target.log
  # Large real seeds are cut to max_len; inputs that fit are fuzzed whole.
  if "$exe" -max_total_time="$seconds" -max_len=32768 -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$artifacts/${target}-" -print_final_stats=1 "$work/$target" >"$log" 2>&1; then
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz_$target: clean, $runs runs in ${seconds}s"
  else
    echo "fuzz_$target: FAILED (log below, reproducer in $artifacts)"
    grep -E "ERROR|SUMMARY|terminate|uncaught|what\(\)" "$log" | head -20 || tail -30 "$log"
    cp "$log" "$artifacts/$target.log"
    failed+=("$target")
  fi
done
rm -rf "$work"
if [ ${#failed[@]} -gt 0 ]; then
  echo "failed: ${failed[*]}" >&2
  exit 1
fi
echo "all fuzz targets clean"
