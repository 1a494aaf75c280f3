// geods edt: the exact Euclidean distance transform of a mask volume or image.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <variant>
#include <vector>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "geods/field/edt.hpp"
#include "geods/io/image_io.hpp"
#include "geods/io/npy.hpp"
#include "geods/io/volume_io.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

// A mask (nonzero = foreground) and the shape its outputs are written in (C order, x last).
struct Mask {
  Grid3<std::uint8_t> grid;
  std::vector<std::size_t> shape;
};

class EdtCommand : public Command {
 public:
  std::string name() const override { return "edt"; }
  std::string summary() const override {
    return "exact Euclidean distance transform of a mask: each nonzero sample's distance to the nearest zero";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "mask", mask_,
              "Mask: .npy (1-, 2- or 3-D, any numeric dtype), .nrrd/.nhdr, .nii/.nii.gz, or an image "
              "(.png, .bmp, .jpg: the first channel); nonzero = foreground");
    add_output(app, "-o,--output", output_, "Distances as float64 of the mask's shape", io::OutputKind::array)->required();
    app.add_option("--spacing", spacing_,
                   "Sample spacing along x, y(, z) (default: the file's, 1 for .npy and images)")
        ->delimiter(',');
    app.add_flag("--squared", squared_, "Write squared distances");
    add_output(app, "--indices", indices_,
               "Also write the flat (C-order) index of each sample's nearest zero sample, int64 (-1: none)",
               io::OutputKind::array);
  }

  void run(const RunContext&, Report& report) override {
    const Mask mask = read_mask();
    const std::size_t axes = mask.shape.size();
    field::EdtRequest request;
    request.squared = squared_;
    request.features = !indices_.empty();
    if (!spacing_.empty()) {
      if (spacing_.size() != axes)
        throw Error(fmt::format("edt: --spacing needs {} values (x first) for this {}-D mask, got {}", axes, axes,
                                spacing_.size()));
      std::array<double, 3> s{1, 1, 1};
      std::copy(spacing_.begin(), spacing_.end(), s.begin());
      request.spacing = s;
    }
    Stopwatch watch;
    const field::EdtResult r = field::edt(mask.grid.view(), request);
    const double compute_s = watch.seconds();
    io::write_npy(output_, std::span<const double>(r.distance.data), mask.shape);
    if (!indices_.empty()) {
      std::vector<std::int64_t> ids(r.features.size());
      for (std::size_t i = 0; i < ids.size(); ++i)
        ids[i] = r.features[i] == field::EdtResult::kNoFeature ? -1 : std::int64_t(r.features[i]);
      io::write_npy(indices_, std::span<const std::int64_t>(ids), mask.shape);
    }

    double max_distance = 0;
    for (const double d : r.distance.data) max_distance = std::max(max_distance, d);
    const std::array<double, 3> spacing = request.spacing.value_or(
        std::array<double, 3>{mask.grid.spacing[0], mask.grid.spacing[1], mask.grid.spacing[2]});
    Json& j = report.json;
    j["mask"] = mask_;
    j["dims"] = std::vector<std::size_t>(mask.grid.dims.begin(), mask.grid.dims.begin() + axes);
    j["spacing"] = std::vector<double>(spacing.begin(), spacing.begin() + axes);
    j["samples"] = r.distance.size();
    j["foreground"] = r.foreground;
    j["max_distance"] = max_distance;  // +inf (null in JSON) without background
    j["squared"] = squared_;
    j["compute_s"] = compute_s;
    j["output"] = output_;
    if (!indices_.empty()) j["indices"] = indices_;
    report.lines.push_back(fmt::format("edt: {} ({}), {} of {} samples foreground", mask_,
                                       fmt::join(mask.grid.dims.begin(), mask.grid.dims.begin() + axes, " x "),
                                       r.foreground, r.distance.size()));
    report.lines.push_back(fmt::format("  largest {}distance {:.6g}, computed in {:.3f} s", squared_ ? "squared " : "",
                                       max_distance, compute_s));
    report.lines.push_back("  wrote " + output_ + (indices_.empty() ? "" : " and " + indices_));
  }

 private:
  Mask read_mask() const {
    const std::string ext = std::filesystem::path(mask_).extension().string();
    Mask m;
    if (ext == ".npy") {
      const io::NpyArray a = io::read_npy(mask_);
      if (a.shape.empty() || a.shape.size() > 3)
        throw Error(fmt::format("{}: the mask must be a 1-, 2- or 3-D array, got {}-D", mask_, a.shape.size()));
      const std::vector<double> values = a.to_vector<double>();
      m.shape = a.shape;
      m.grid.dims = {1, 1, 1};
      std::copy(a.shape.rbegin(), a.shape.rend(), m.grid.dims.begin());
      m.grid.data.resize(values.size());
      for (std::size_t i = 0; i < values.size(); ++i) {
        if (std::isnan(values[i])) throw Error(mask_ + ": the mask holds NaN");
        m.grid.data[i] = values[i] != 0;
      }
      return m;
    }
    if (ext == ".png" || ext == ".bmp" || ext == ".jpg" || ext == ".jpeg") {
      const Image<std::uint8_t> im = io::read_image(mask_);
      m.shape = {im.height, im.width};
      m.grid.dims = {im.width, im.height, 1};
      m.grid.data.resize(im.width * im.height);
      for (std::size_t i = 0; i < m.grid.data.size(); ++i) m.grid.data[i] = im.data[i * im.channels] != 0;
      return m;
    }
    const io::AnyGrid3 volume = io::read_volume(mask_);
    std::visit(
        [&](const auto& g) {
          static_cast<Grid3Geometry&>(m.grid) = g;
          m.grid.data.resize(g.data.size());
          for (std::size_t i = 0; i < g.data.size(); ++i) {
            if constexpr (std::is_floating_point_v<typename std::decay_t<decltype(g)>::value_type>)
              if (std::isnan(g.data[i])) throw Error(mask_ + ": the mask holds NaN");
            m.grid.data[i] = g.data[i] != 0;
          }
        },
        volume);
    m.shape = {m.grid.dims[2], m.grid.dims[1], m.grid.dims[0]};
    return m;
  }

  std::string mask_, output_, indices_;
  std::vector<double> spacing_;
  bool squared_ = false;
};

const bool registered_edt = register_command<EdtCommand>();

}  // namespace
}  // namespace geods::cli
