// Demo steps of the shape module: the D2 shape distributions of simple shapes
// and of the data/ meshes (as the seed's Figure 55), and a query mesh with its
// five nearest shapes of the furniture library, rendered as thumbnails.
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "demo.hpp"
#include "geods/io/image_io.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/io/svg.hpp"
#include "geods/ray/render.hpp"
#include "geods/shape/analytic_shapes.hpp"
#include "geods/shape/collection.hpp"
#include "geods/shape/retrieval.hpp"
#include "geods/shape/stats_fields.hpp"
#include "stats_text.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

struct Curve {
  std::string name;
  std::vector<float> histogram;  // over [0, xmax)
  std::string colour;
};

// Densities (histogram / bin width) against x, with axes, ticks and a legend.
void plot(const std::filesystem::path& path, const std::string& title, const std::vector<Curve>& curves, double xmax,
          const std::string& xlabel) {
  double ymax = 0;
  for (const Curve& c : curves)
    for (float v : c.histogram) ymax = std::max(ymax, double(v) * double(c.histogram.size()) / xmax);
  ymax *= 1.1;
  const double w = 10, h = 5;  // plot area in world units
  io::SvgWriter svg(AABB2d(Vec2d(-1.0, -0.8), Vec2d(w + 0.3, h + 0.3)), 800);
  svg.title(title);
  auto at = [&](double x, double y) { return Vec2d(x / xmax * w, y / ymax * h); };
  const io::SvgStyle axis{.stroke = "#444", .stroke_width = 1.0}, grid{.stroke = "#ddd", .stroke_width = 0.5};
  for (int i = 0; i <= 7; ++i) {
    const double x = xmax * i / 7;
    svg.segment(at(x, 0), at(x, ymax), grid);
    svg.label(at(x, 0) + Vec2d(-0.1, -0.35), fmt::format("{:.3g}", x), {.stroke = "none", .fill = "#444", .font_size = 11});
  }
  for (int i = 0; i <= 4; ++i) {
    const double y = ymax * i / 4;
    svg.segment(at(0, y), at(xmax, y), grid);
    svg.label(at(0, y) + Vec2d(-0.9, -0.05), fmt::format("{:.2g}", y), {.stroke = "none", .fill = "#444", .font_size = 11});
  }
  svg.segment(at(0, 0), at(xmax, 0), axis);
  svg.segment(at(0, 0), at(0, ymax), axis);
  svg.label(Vec2d(w / 2 - 0.5, -0.75), xlabel, {.stroke = "none", .fill = "#222", .font_size = 13});
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const Curve& curve = curves[c];
    const std::size_t bins = curve.histogram.size();
    std::vector<Vec2d> line;
    for (std::size_t i = 0; i < bins; ++i)
      line.push_back(at(xmax * (double(i) + 0.5) / double(bins), double(curve.histogram[i]) * double(bins) / xmax));
    svg.polyline(line, {.stroke = curve.colour, .stroke_width = 2.0});
    const Vec2d key(w - 2.6, h - 0.4 - 0.4 * double(c));
    svg.segment(key, key + Vec2d(0.4, 0), {.stroke = curve.colour, .stroke_width = 3.0});
    svg.label(key + Vec2d(0.55, -0.08), curve.name, {.stroke = "none", .fill = "#222", .font_size = 13});
  }
  svg.save(path);
}

const char* kColours[] = {"#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"};

void run_distributions(const DemoContext& context, DemoResult& result) {
  // Figure 55: raw distances (no normalization) of simple shapes of similar size.
  shape::DistributionOptions raw;
  raw.normalization = shape::Normalization::none;
  raw.max_value = 7;
  raw.bins = 70;
  raw.samples = 1 << 18;
  const std::pair<const char*, TriMesh> simple[] = {
      {"torus (R 2, r 0.75)", shape::torus_mesh(2, 0.75f)},
      {"sphere (r 2)", shape::icosphere(4, 2)},
      {"cylinder (r 1.5, h 4)", shape::cylinder_mesh(96, 1.5f, 4)},
      {"cube (side 3)", shape::box_mesh(3, 3, 3)}};
  std::vector<Curve> curves;
  Stopwatch watch;
  for (const auto& [name, mesh] : simple)
    curves.push_back({name, shape::shape_distribution(mesh, shape::ShapeFunction::d2, raw), kColours[curves.size()]});
  result.timing("4 raw D2 distributions (2^18 samples each)", watch.seconds());
  plot(context.out_dir / "shape_d2_figure55.svg", "D2 of simple shapes", curves, raw.max_value, "distance");
  result.figures.push_back({"shape_d2_figure55.svg",
                            "The seed's Figure 55: D2 (distance between two random surface points) of a torus, a "
                            "sphere, a cylinder and a cube, as densities over the raw distance. The sphere's is "
                            "the line d / (2 R^2) up to 2R = 4."});

  // The data meshes, mean-normalized: the descriptors the database compares.
  shape::DistributionOptions normalized;
  normalized.samples = 1 << 17;
  curves.clear();
  watch = Stopwatch();
  for (const char* file : {"bunny.ply", "teapot.obj"})
    curves.push_back({file, shape::shape_distribution(io::read_mesh(context.data_dir / file), shape::ShapeFunction::d2,
                                                      normalized),
                      kColours[curves.size()]});
  const shape::ShapeCollection furniture = shape::ShapeCollection::open(context.data_dir / "furniture.sh3f");
  for (const char* model : {"rock1", "upperCabinet", "crate", "JapaneseLantern"})
    for (std::size_t i = 0; i < furniture.size(); ++i)
      if (furniture.entries()[i].name.find("/" + std::string(model) + "/") != std::string::npos)
        curves.push_back({furniture.entries()[i].title + " (furniture.sh3f)",
                          shape::shape_distribution(furniture.read(i), shape::ShapeFunction::d2, normalized),
                          kColours[curves.size()]});
  result.timing("6 normalized D2 distributions of data/ meshes", watch.seconds());
  plot(context.out_dir / "shape_d2_data.svg", "D2 of the data meshes", curves, 3.0, "distance / mean distance");
  result.figures.push_back({"shape_d2_data.svg",
                            "D2 of data/ meshes, each normalized by its mean distance (invariant to rotation, "
                            "translation, scale and tessellation): the feature vectors of the retrieval database."});
  result.stat("samples (raw / normalized)", fmt::format("{} / {}", raw.samples, normalized.samples));
  result.text =
      "Shape distributions (seed §5.6, Osada et al.): a shape function of random points on the surface, "
      "evaluated many times, binned into a histogram. D2, the distance between two points, tells a sphere "
      "(a straight ramp), a cube, a cylinder and a torus (two humps: across the hole and around it) apart.";
}

// Renders `mesh` into a thumbnail and copies it into the strip at column `slot`.
void thumbnail(const TriMesh& mesh, Image<std::uint8_t>& strip, std::size_t slot, std::size_t size) {
  ray::RenderOptions options;
  options.width = options.height = int(size);
  const Image<std::uint8_t> im = ray::render(mesh, options).image;
  for (std::size_t y = 0; y < size; ++y)
    for (std::size_t x = 0; x < size; ++x)
      for (std::size_t c = 0; c < 3; ++c) strip(slot * (size + 8) + x, y, c) = im(x, y, c);
}

void run_retrieval(const DemoContext& context, DemoResult& result) {
  const shape::ShapeCollection furniture = shape::ShapeCollection::open(context.data_dir / "furniture.sh3f");
  shape::DescriptorOptions options = shape::parse_descriptor("combined");
  Stopwatch watch;
  shape::CollectionIndex index = shape::index_collection(furniture, options, context.progress);
  result.timing("index furniture.sh3f (combined D2 + A3 + D3)", watch.seconds());
  shape::ShapeDatabase& db = index.database;
  // The bunny and the teapot join through the dynamization (no rebuild).
  for (const char* file : {"bunny.ply", "teapot.obj"}) db.add(file, io::read_mesh(context.data_dir / file), "data");

  // The query: the upper cabinet turned, moved, scaled and subdivided.
  std::size_t cabinet = 0;
  for (std::size_t i = 0; i < furniture.size(); ++i)
    if (furniture.entries()[i].name.find("/upperCabinet/") != std::string::npos) cabinet = i;
  TriMesh query = furniture.read(cabinet);
  const Eigen::Matrix3f turn = Eigen::AngleAxisf(0.6f, Vec3f(0, 1, 0)).toRotationMatrix();
  for (Vec3f& v : query.vertices) v = 0.5f * (turn * v) + Vec3f(10, 0, -3);
  watch = Stopwatch();
  const std::vector<shape::ShapeMatch> matches = db.query(query, 5);
  result.timing("query (describe + 5 nearest)", watch.seconds());

  const std::size_t size = 160;
  Image<std::uint8_t> strip(6 * (size + 8) - 8, size, 3, 255);
  thumbnail(query, strip, 0, size);
  std::string caption = "Query (left): the upper cabinet of furniture.sh3f, rotated 0.6 rad, scaled by 0.5, moved; "
                        "then its 5 nearest shapes:";
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const shape::ShapeMatch& m = matches[i];
    const TriMesh mesh = m.label == "data" ? io::read_mesh(context.data_dir / m.name)
                                           : furniture.read(std::size_t(std::find_if(furniture.entries().begin(),
                                                                                     furniture.entries().end(),
                                                                                     [&](const auto& e) {
                                                                                       return e.name == m.name;
                                                                                     }) -
                                                                        furniture.entries().begin()));
    thumbnail(mesh, strip, i + 1, size);
    caption += fmt::format(" {}. {} [{}] at {:.4f};", i + 1, m.name.substr(m.name.rfind('/') + 1), m.label, m.distance);
  }
  caption.back() = '.';
  caption += " The copy's distance is 0 because the same seed picks the same random points on the congruent "
             "surface, moved with it; the next ones are what D2 + A3 + D3 finds similar.";
  io::write_png(context.out_dir / "shape_query.png", strip);
  result.figures.push_back({"shape_query.png", caption});

  const shape::RetrievalScores scores = shape::evaluate_retrieval(db, 3);
  result.stat("database", stats_text(db.stats()));
  result.stat("retrieval (leave-one-out, k = 3)",
              fmt::format("nearest neighbor {:.2f}, precision at 3 {:.2f}, first tier {:.2f}, second tier {:.2f}",
                          scores.nn_rate, scores.precision_at_k, scores.first_tier, scores.second_tier));
  result.text = fmt::format(
      "A shape database (seed §5.6, steps 3 and 4): the {} models of data/furniture.sh3f described by combined "
      "D2, A3 and D3 histograms in a k-d tree, the bunny and the teapot added through the dynamization. The query, "
      "a transformed copy of one model, finds that model first.",
      furniture.size());
}

const bool registered_distributions = register_demo_step(
    {"shape", "distributions", "Shape distributions: D2 of simple shapes (Figure 55) and of data/ meshes", &run_distributions});
const bool registered_retrieval =
    register_demo_step({"shape", "retrieval", "Shape retrieval: a query and its 5 nearest shapes", &run_retrieval});

}  // namespace
}  // namespace geods::cli
