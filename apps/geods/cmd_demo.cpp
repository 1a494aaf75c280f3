// geods demo --out DIR: runs every registered demo step and writes DIR/index.html.
#include <fmt/format.h>

#include <string>

#include "command.hpp"
#include "demo.hpp"
#include "geods/core/error.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

namespace fs = std::filesystem;

// The data/ folder of the source tree when it is still there, else ./data.
fs::path default_data_dir() {
  const fs::path built_in = GEODS_DATA_DIR;
  return fs::is_directory(built_in) ? built_in : fs::path("data");
}

class DemoCommand : public Command {
 public:
  std::string name() const override { return "demo"; }
  std::string summary() const override {
    return "Run every capability on the data sets and write a gallery DIR/index.html";
  }
  void add_options(CLI::App& app) override {
    app.add_option("--out,-o", out_, "Output folder")->required();
    app.add_option("--data", data_, "Folder of the data sets (default: the source tree's data/)");
    app.add_option("--only", only_, "Run only these steps (module or module/name)");
  }
  void run(const RunContext& context, Report& report) override {
    const fs::path data = data_.empty() ? default_data_dir() : fs::path(data_);
    if (!fs::is_directory(data)) throw Error(data.string() + ": data folder not found (use --data DIR)");
    std::error_code ec;
    fs::create_directories(out_, ec);
    if (ec || !fs::is_directory(out_)) throw Error(out_ + ": cannot create output folder");

    const DemoContext demo{data, out_, context.progress};
    std::vector<DemoOutcome> outcomes;
    Stopwatch total;
    int failed = 0;
    Json steps = Json::array();
    for (const DemoStep* step : demo_steps()) {
      if (!selected(*step)) continue;
      DemoOutcome outcome{step, {}, 0, {}};
      Stopwatch watch;
      try {
        step->run(demo, outcome.result);
      } catch (const std::exception& e) {
        outcome.error = e.what();
        ++failed;
      }
      outcome.seconds = watch.seconds();
      Json stats = Json::object();
      for (const auto& [k, v] : outcome.result.stats) stats[k] = v;
      Json timings = Json::object();
      for (const auto& [k, v] : outcome.result.timings) timings[k] = v;
      steps.push_back({{"module", step->module}, {"name", step->name}, {"ok", outcome.error.empty()},
                       {"error", outcome.error}, {"seconds", outcome.seconds}, {"stats", stats}, {"timings", timings}});
      report.lines.push_back(fmt::format("  {:<24} {:8.3f} s  {}", step->module + "/" + step->name, outcome.seconds,
                                         outcome.error.empty() ? "ok" : "FAILED: " + outcome.error));
      outcomes.push_back(std::move(outcome));
    }
    if (outcomes.empty()) throw Error("no demo step matches --only");
    write_demo_gallery(out_, outcomes);
    const std::string gallery = (fs::path(out_) / "index.html").string();
    report.lines.push_back(fmt::format("{} steps, {} failed; gallery: {}", outcomes.size(), failed, gallery));
    report.json["out"] = out_;
    report.json["data"] = data.string();
    report.json["gallery"] = gallery;
    report.json["steps"] = steps;
    report.json["failed_steps"] = failed;
    report.json["compute_s"] = total.seconds();
  }

 private:
  bool selected(const DemoStep& step) const {
    if (only_.empty()) return true;
    for (const std::string& s : only_) {
      if (s == step.module || s == step.module + "/" + step.name) return true;
    }
    return false;
  }

  std::string out_;
  std::string data_;
  std::vector<std::string> only_;
};

const bool registered_demo = register_command<DemoCommand>();

}  // namespace
}  // namespace geods::cli
