#pragma once
// A structure's stats as one line of text for the demo's tables, generated
// from the library's field lists (<module>/stats_fields.hpp), so no field is
// spelled twice. The JSON form is stats_json.hpp.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <string>

namespace geods::cli {

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
