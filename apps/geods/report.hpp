#pragma once
// What a command or a demo step reports, as JSON. Its own header so that code
// that only builds a report (the demo steps, file_info) does not compile the
// command-line parser (CLI11 emits its validators and formatters into every
// file that includes it: about 7 s a file at -O3).
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace geods::cli {

using Json = nlohmann::ordered_json;

/// What a command reports: `json` is printed with --json (inputs, parameters,
/// counts, timings in keys ending in _s), `lines` otherwise.
struct Report {
  Json json = Json::object();
  std::vector<std::string> lines;
};

}  // namespace geods::cli
