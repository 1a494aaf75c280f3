// geods shapes: shape retrieval with shape distributions (seed §5.6):
//   index COLLECTION -o DB   describe a collection's meshes into a database
//   query DB MESH            the k nearest shapes to a mesh
//   evaluate COLLECTION      retrieval quality of a labelled collection (PSB measures)
#include <fmt/format.h>

#include <filesystem>
#include <algorithm>
#include <iostream>
#include <map>
#include <optional>

#include "command.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/shape/collection.hpp"
#include "geods/shape/retrieval.hpp"
#include "geods/shape/stats_fields.hpp"
#include "stats_json.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

namespace fs = std::filesystem;

// The descriptor options every subcommand that describes meshes takes.
struct DescriptorArgs {
  std::string descriptor = "d2", normalization = "mean";
  std::size_t samples = shape::DistributionOptions{}.samples, bins = shape::DistributionOptions{}.bins;
  std::uint64_t seed = 0;

  void add_options(CLI::App& app) {
    app.add_option("--descriptor", descriptor,
                   "Shape function(s): d1, d2, a3, d3, d4, combined (d2+a3+d3) or e.g. d2+a3:0.5 (default d2)");
    app.add_option("--samples", samples, "Shape function evaluations per distribution (default 65536)");
    app.add_option("--bins", bins, "Histogram bins per distribution (default 64)");
    app.add_option("--seed", seed, "Seed of the random surface points (default 0)");
    app.add_option("--normalization", normalization, "Scale normalization: mean (default) or median");
  }
  shape::DescriptorOptions options() const {
    shape::DescriptorOptions o = shape::parse_descriptor(descriptor);
    o.distribution.samples = samples;
    o.distribution.bins = bins;
    o.distribution.seed = seed;
    o.distribution.normalization = shape::parse_normalization(normalization);
    if (o.distribution.normalization == shape::Normalization::none)
      throw Error("--normalization none is not scale-invariant; use mean or median");
    shape::check_descriptor(o);
    return o;
  }
};

std::string_view kind_name(shape::CollectionKind k) {
  return k == shape::CollectionKind::directory ? "directory" : k == shape::CollectionKind::zip ? "zip" : "sh3f";
}

// Opens and indexes a collection; warns on stderr about each skipped member.
shape::ShapeCollection open_collection(const std::string& path, const std::string& labels) {
  return shape::ShapeCollection::open(path, labels);
}

// Indexes an opened collection; warns on stderr about each skipped member.
shape::CollectionIndex index(const shape::ShapeCollection& collection, const std::string& labels,
                             const shape::DescriptorOptions& o, const RunContext& context, Json& j, double& seconds) {
  const std::string path = collection.path().string();
  for (const std::string& w : collection.warnings()) std::cerr << "geods shapes: warning: " << w << "\n";
  Stopwatch watch;
  shape::CollectionIndex result = shape::index_collection(collection, o, context.progress);
  seconds = watch.seconds();
  for (const auto& s : result.skipped) std::cerr << "geods shapes: warning: skipped " << s.name << ": " << s.reason << "\n";
  j["collection"] = path;
  j["kind"] = kind_name(collection.kind());
  if (!labels.empty()) j["labels"] = labels;
  j["members"] = collection.size();
  j["skipped"] = result.skipped.size();
  Json skipped = Json::array();
  for (const auto& s : result.skipped) skipped.push_back({{"name", s.name}, {"reason", s.reason}});
  j["skipped_shapes"] = skipped;
  j["descriptor"] = shape::descriptor_name(o);
  j["samples"] = o.distribution.samples;
  j["bins"] = o.distribution.bins;
  j["normalization"] = shape::normalization_name(o.distribution.normalization);
  return result;
}

class ShapesCommand : public Command {
 public:
  std::string name() const override { return "shapes"; }
  std::string summary() const override {
    return "shape retrieval with shape distributions: index a collection, query it, evaluate it (PSB measures)";
  }
  void add_options(CLI::App& app) override {
    app.require_subcommand(1);
    index_ = app.add_subcommand("index", "Describe every mesh of a collection (directory, .zip, .sh3f) into a database");
    index_->fallthrough();
    index_->add_option("collection", collection_, "Directory tree of meshes, zip archive or Sweet Home 3D .sh3f library")
        ->required();
    index_->add_option("-o,--output", output_, "Output database (.geodsshapes; ShapeDatabase.load reads it)")->required();
    index_->add_option("--labels", labels_, "CSV of path,label rows (default: the .sh3f catalog's categories)");
    index_->add_flag("--append", append_, "Add the shapes to the database OUTPUT already holds (its descriptor options)");
    descriptor_.add_options(*index_);

    query_ = app.add_subcommand("query", "The k nearest shapes of a database to a mesh");
    query_->fallthrough();
    query_->add_option("database", database_, "Database written by `geods shapes index`")->required();
    query_->add_option("mesh", mesh_, "Query mesh (PLY, OBJ, STL, OFF, glTF)")->required();
    query_->add_option("--k", k_, "Shapes to return (default 5)")->check(CLI::PositiveNumber);
    query_->add_option("--eps", eps_, "Approximate: distances within (1 + eps) of the true ones (default 0: exact)");

    evaluate_ = app.add_subcommand("evaluate", "Retrieval quality of a labelled collection or database "
                                               "(nearest neighbor, precision at k, first and second tier)");
    evaluate_->fallthrough();
    evaluate_->add_option("collection", collection_, "Collection (directory, .zip, .sh3f) or a database file")->required();
    evaluate_->add_option("--labels", labels_, "CSV of path,label rows (default: the .sh3f catalog's categories)");
    evaluate_->add_option("--k", k_, "k of precision at k (default 5)")->check(CLI::PositiveNumber);
    descriptor_.add_options(*evaluate_);
  }

  void run(const RunContext& context, Report& report) override {
    if (index_->parsed()) return run_index(context, report);
    if (query_->parsed()) return run_query(report);
    return run_evaluate(context, report);
  }

 private:
  void run_index(const RunContext& context, Report& report) {
    Json& j = report.json;
    shape::DescriptorOptions o = descriptor_.options();
    std::optional<shape::ShapeDatabase> existing;
    if (append_) {
      if (!fs::exists(output_)) throw Error("index: --append needs an existing database " + output_);
      existing.emplace(shape::ShapeDatabase::load(output_));
      o = existing->options();
    }
    double index_s = 0;
    shape::CollectionIndex result = index(open_collection(collection_, labels_), labels_, o, context, j, index_s);
    double add_s = 0;
    if (existing) {
      const shape::ShapeDatabase& fresh = result.database;
      Stopwatch watch;
      for (std::uint64_t id = 0; id < fresh.size(); ++id) {  // one by one: the dynamization's inserts
        const std::vector<float> d = fresh.descriptor(id);
        existing->add_descriptors(std::span(&fresh.name(id), 1), d, std::span(&fresh.label(id), 1));
      }
      add_s = watch.seconds();
      result.database = std::move(*existing);
    }
    const shape::ShapeDatabase& db = result.database;
    if (db.empty()) throw Error("index: " + collection_ + ": no mesh could be read");
    db.save(output_);
    j["append"] = append_;
    put_stats(j, db.stats());
    j["index_s"] = index_s;
    if (append_) j["add_s"] = add_s;
    j["compute_s"] = index_s + add_s;
    j["output"] = output_;
    report.lines.push_back(fmt::format("shapes index: {} ({}) -> {} shapes{}, {} skipped; {} x {} bins, {} samples",
                                       collection_, j["kind"].get<std::string>(), db.size(),
                                       append_ ? " (appended)" : "", result.skipped.size(), shape::descriptor_name(o),
                                       o.distribution.bins, o.distribution.samples));
    report.lines.push_back(fmt::format("  described in {:.3f} s; {} labels; wrote {}", index_s + add_s,
                                       db.stats().labels, output_));
  }

  void run_query(Report& report) {
    if (!(eps_ >= 0)) throw Error("query: --eps must be >= 0");
    const shape::ShapeDatabase db = shape::ShapeDatabase::load(database_);
    const TriMesh mesh = io::read_mesh(mesh_);
    Stopwatch describe_watch;
    const std::vector<float> descriptor = db.describe(mesh);
    const double describe_s = describe_watch.seconds();
    Stopwatch query_watch;
    const std::vector<shape::ShapeMatch> matches = db.query_descriptor(descriptor, k_, eps_);
    const double query_s = query_watch.seconds();
    Json& j = report.json;
    j["database"] = database_;
    j["mesh"] = mesh_;
    j["triangles"] = mesh.triangles.size();
    j["k"] = k_;
    j["eps"] = eps_;
    j["descriptor"] = shape::descriptor_name(db.options());
    Json results = Json::array();
    for (const auto& m : matches) results.push_back({{"name", m.name}, {"label", m.label}, {"distance", m.distance}});
    j["results"] = results;
    put_stats(j, db.stats(), "database_");
    j["describe_s"] = describe_s;
    j["query_s"] = query_s;
    j["compute_s"] = describe_s + query_s;
    report.lines.push_back(fmt::format("shapes query: {} in {} ({} shapes), {} nearest:", mesh_, database_, db.size(),
                                       matches.size()));
    for (const auto& m : matches)
      report.lines.push_back(fmt::format("  {:.5f}  {}{}", m.distance, m.name, m.label.empty() ? "" : "  [" + m.label + "]"));
    report.lines.push_back(fmt::format("  described in {:.4f} s, searched in {:.6f} s", describe_s, query_s));
  }

  void run_evaluate(const RunContext& context, Report& report) {
    Json& j = report.json;
    std::optional<shape::ShapeDatabase> loaded;
    double index_s = 0;
    std::size_t skipped = 0;
    bool is_database = false;  // a geods archive of a database rather than a collection
    if (fs::is_regular_file(collection_)) {
      try {
        is_database = Archive::peek(collection_).kind == shape::kShapeDatabaseArchiveKind;
      } catch (const Error&) {
      }
    }
    if (is_database) {
      if (!labels_.empty()) throw Error("evaluate: --labels goes with a collection, not a database");
      loaded.emplace(shape::ShapeDatabase::load(collection_));
      j["database"] = collection_;
    } else {
      const shape::DescriptorOptions o = descriptor_.options();
      const shape::ShapeCollection collection = open_collection(collection_, labels_);
      std::map<std::string, std::size_t> class_size;
      for (const auto& e : collection.entries())
        if (!e.label.empty()) ++class_size[e.label];
      if (std::none_of(class_size.begin(), class_size.end(), [](const auto& c) { return c.second >= 2; }))
        throw Error("evaluate: " + collection_ + ": no label has two shapes (give labels with --labels path,label rows)");
      shape::CollectionIndex result = index(collection, labels_, o, context, j, index_s);
      skipped = result.skipped.size();
      loaded.emplace(std::move(result.database));
    }
    const shape::RetrievalScores s = shape::evaluate_retrieval(*loaded, k_);
    if (s.queries == 0)
      throw Error("evaluate: " + collection_ + ": no labelled class has two readable shapes");
    put_stats(j, s);
    j["recall"] = s.recall;
    j["precision"] = s.precision;
    j["index_s"] = index_s;
    j["evaluate_s"] = s.compute_s;
    j["compute_s"] = index_s + s.compute_s;
    report.lines.push_back(fmt::format("shapes evaluate: {}: {} shapes ({} queries in {} classes{})", collection_,
                                       s.shapes, s.queries, s.classes,
                                       skipped ? fmt::format(", {} skipped", skipped) : std::string()));
    report.lines.push_back(fmt::format("  nearest neighbor {:.3f}, precision at {} {:.3f}, first tier {:.3f}, "
                                       "second tier {:.3f}, mean average precision {:.3f}",
                                       s.nn_rate, s.k, s.precision_at_k, s.first_tier, s.second_tier,
                                       s.mean_average_precision));
    report.lines.push_back(fmt::format("  indexed in {:.3f} s, evaluated in {:.3f} s", index_s, s.compute_s));
  }

  CLI::App *index_ = nullptr, *query_ = nullptr, *evaluate_ = nullptr;
  std::string collection_, output_, labels_, database_, mesh_;
  bool append_ = false;
  std::size_t k_ = 5;
  double eps_ = 0;
  DescriptorArgs descriptor_;
};

const bool registered_shapes = register_command<ShapesCommand>();

}  // namespace
}  // namespace geods::cli
