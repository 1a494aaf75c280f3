#pragma once
// A structure's stats in a command's JSON report and in the demo, generated
// from the library's field lists (<module>/stats_fields.hpp), so no field is
// spelled twice.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <string>

#include "command.hpp"

namespace geods::cli {

/// Writes each field of `stats` into `json` as `prefix + name` (the prefix
/// names the structure's role when it is not what the command is about:
/// "tree_", "accel_", "locator_").
template <typename Stats>
void put_stats(Json& json, const Stats& stats, const std::string& prefix = "") {
  for_each_field(stats, [&](const char* name, const auto& value) { json[prefix + name] = value; });
}

/// "points 4996, nodes 999, ...": the fields of `stats` for the demo's tables.
template <typename Stats>
std::string stats_text(const Stats& stats) {
  std::string text;
  for_each_field(stats, [&](const char* name, const auto& value) {
    if (!text.empty()) text += ", ";
    text += fmt::format("{} {}", name, value);
  });
  return text;
}

}  // namespace geods::cli
