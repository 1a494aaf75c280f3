#pragma once
// Demo steps: each module registers its steps in one line, e.g.
//   const bool registered = register_demo_step({"spatial", "quadtree", "Quadtree and its balanced version", &run});
// `geods demo --out DIR` runs them in module order and writes DIR/index.html.
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "geods/core/progress.hpp"

namespace geods::cli {

struct DemoContext {
  std::filesystem::path data_dir;  // the data sets (data/ of the source tree)
  std::filesystem::path out_dir;   // where figures and files go
  ProgressCallback progress;
};

/// What a step shows: figures and files (paths relative to out_dir) and statistics.
struct DemoResult {
  struct Figure {
    std::string file;
    std::string caption;
  };
  std::string text;                                        // a paragraph above the figures
  std::vector<Figure> figures;                             // .svg / .png shown inline
  std::vector<Figure> files;                               // other outputs, linked
  std::vector<std::pair<std::string, std::string>> stats;  // name, value
  std::vector<std::pair<std::string, double>> timings;     // name, seconds

  void stat(std::string name, std::string value) { stats.emplace_back(std::move(name), std::move(value)); }
  void timing(std::string name, double seconds) { timings.emplace_back(std::move(name), seconds); }
};

struct DemoStep {
  std::string module;  // one of the modules of DESIGN.md; steps run in module order
  std::string name;
  std::string title;
  std::function<void(const DemoContext&, DemoResult&)> run;
};

bool register_demo_step(DemoStep step);
/// Registered steps sorted by module order, then name.
std::vector<const DemoStep*> demo_steps();

/// A finished step for the gallery.
struct DemoOutcome {
  const DemoStep* step;
  DemoResult result;
  double seconds = 0;
  std::string error;  // non-empty if the step failed
};

/// Writes out_dir/index.html, one section per outcome.
void write_demo_gallery(const std::filesystem::path& out_dir, const std::vector<DemoOutcome>& outcomes);

}  // namespace geods::cli
