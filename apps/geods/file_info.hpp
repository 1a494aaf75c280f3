#pragma once
// What a file holds: the engine of `geods info` and of the demo's info step.
#include <array>
#include <filesystem>
#include <optional>

#include "geods/core/dtype.hpp"
#include "report.hpp"

namespace geods::cli {

/// Dimensions and sample type of a headerless volume file.
struct RawVolumeSpec {
  std::array<std::size_t, 3> dims;
  DType dtype;
};

/// Reads `path` by its extension (mesh, volume, image, points, segments or a
/// plain .npy array) and describes it: kind, counts, bounds, dtype and dims,
/// validity problems. Throws geods::Error for unreadable or malformed files.
Report describe_file(const std::filesystem::path& path, const std::optional<RawVolumeSpec>& raw = {});

}  // namespace geods::cli
