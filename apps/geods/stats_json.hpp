#pragma once
// A structure's stats in a command's JSON report, generated from the library's
// field lists (<module>/stats_fields.hpp), so no field is spelled twice. The
// demo's text form is stats_text.hpp.
#include <string>

#include "report.hpp"

namespace geods::cli {

/// Writes each field of `stats` into `json` as `prefix + name` (the prefix
/// names the structure's role when it is not what the command is about:
/// "tree_", "accel_", "locator_").
template <typename Stats>
void put_stats(Json& json, const Stats& stats, const std::string& prefix = "") {
  for_each_field(stats, [&](const char* name, const auto& value) { json[prefix + name] = value; });
}

}  // namespace geods::cli
