// geods info FILE: what a file holds.
#include <array>
#include <string>

#include "command.hpp"
#include "file_info.hpp"
#include "geods/core/error.hpp"

namespace geods::cli {
namespace {

class InfoCommand : public Command {
 public:
  std::string name() const override { return "info"; }
  std::string summary() const override {
    return "Describe a mesh, volume, image, point or segment file: counts, bounds, dtype, dims, problems";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "file", file_, "The file to describe");
    app.add_option("--dims", dims_, "Dimensions X,Y,Z of a raw volume")->delimiter(',')->expected(3);
    app.add_option("--dtype", dtype_, "Sample type of a raw volume: u8, u16, i16, f32, f64");
  }
  void run(const RunContext&, Report& report) override {
    std::optional<RawVolumeSpec> raw;
    if (!dims_.empty() || !dtype_.empty()) {
      if (dims_.size() != 3 || dtype_.empty()) throw Error(file_ + ": a raw volume needs both --dims X,Y,Z and --dtype");
      raw = RawVolumeSpec{{dims_[0], dims_[1], dims_[2]}, parse_dtype(dtype_)};
    }
    report = describe_file(file_, raw);
  }

 private:
  std::string file_;
  std::vector<std::size_t> dims_;
  std::string dtype_;
};

const bool registered_info = register_command<InfoCommand>();

}  // namespace
}  // namespace geods::cli
