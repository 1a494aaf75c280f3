# Precompiled headers: the external headers most files of a target include,
# parsed once per target instead of once per file (1.5-3.5 s a file at -O3,
# about twice that with the sanitizers; `make test` compiles ~250 files twice).
# Only external headers: a file that misses a geods include still fails to
# compile. -DCMAKE_DISABLE_PRECOMPILE_HEADERS=ON turns them off.
set(GEODS_PCH_COMMON
    <algorithm> <array> <cmath> <cstdint> <cstring> <filesystem> <fstream> <functional> <limits>
    <map> <memory> <numeric> <optional> <span> <string> <utility> <vector> <Eigen/Core> <Eigen/Geometry>)

# geods_precompile_headers(target [header...]): the common list plus the
# target's own framework (GoogleTest, pybind11, fmt and JSON).
function(geods_precompile_headers target)
  target_precompile_headers(${target} PRIVATE ${GEODS_PCH_COMMON} ${ARGN})
endfunction()
