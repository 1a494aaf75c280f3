#include "geods/shape/shape_database.hpp"

#include <fmt/format.h>

#include <cmath>
#include <set>

#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"

namespace geods::shape {

namespace {

std::size_t dimension_of(const DescriptorOptions& o) {
  check_descriptor(o);
  return o.functions.size() * o.distribution.bins;
}

// Strings as one byte section and n + 1 offsets.
void add_strings(ArchiveWriter& w, const std::string& name, const std::vector<std::string>& strings,
                 std::vector<std::uint8_t>& bytes, std::vector<std::uint64_t>& offsets) {
  offsets.assign(1, 0);
  for (const std::string& s : strings) {
    bytes.insert(bytes.end(), s.begin(), s.end());
    offsets.push_back(bytes.size());
  }
  w.add(name, bytes);
  w.add(name + "_offsets", offsets);
}

std::vector<std::string> read_strings(const Archive& a, const std::string& name, std::size_t count) {
  const FlatArray<std::uint8_t> bytes = a.array<std::uint8_t>(name);
  const FlatArray<std::uint64_t> offsets = a.array<std::uint64_t>(name + "_offsets", count + 1);
  std::vector<std::string> out(count);
  if (offsets[0] != 0) throw a.error(name + ": offsets do not start at 0");
  for (std::size_t i = 0; i < count; ++i) {
    if (offsets[i + 1] < offsets[i] || offsets[i + 1] > bytes.size()) throw a.error(name + ": bad offsets");
    out[i].assign(reinterpret_cast<const char*>(bytes.data()) + offsets[i], offsets[i + 1] - offsets[i]);
  }
  if (offsets[count] != bytes.size()) throw a.error(name + ": bytes after the last string");
  return out;
}

}  // namespace

ShapeDatabase::ShapeDatabase(DescriptorOptions options) : options_(std::move(options)), tree_(dimension_of(options_)) {}

std::vector<float> ShapeDatabase::descriptor(std::uint64_t id) const {
  if (id >= size()) throw Error(fmt::format("ShapeDatabase: no shape {} ({} stored)", id, size()));
  return tree_.point(id);
}

std::vector<float> ShapeDatabase::describe(const TriMesh& mesh) const { return shape::describe(mesh, options_); }

std::uint64_t ShapeDatabase::add(std::string name, const TriMesh& mesh, std::string label) {
  const std::vector<float> d = describe(mesh);
  return insert(std::span(&name, 1), d, std::span(&label, 1)).front();
}

std::vector<std::uint64_t> ShapeDatabase::add(std::span<const std::string> names, std::span<const TriMesh> meshes,
                                              std::span<const std::string> labels) {
  if (names.size() != meshes.size())
    throw Error(fmt::format("ShapeDatabase::add: {} names for {} meshes", names.size(), meshes.size()));
  const std::size_t dim = dimension();
  std::vector<float> rows(meshes.size() * dim);
  std::vector<std::string> errors(meshes.size());
  // One shape per task; the descriptor's own chunks may run in parallel too.
  parallel_for(0, meshes.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      try {
        const std::vector<float> d = describe(meshes[i]);
        std::copy(d.begin(), d.end(), rows.begin() + std::ptrdiff_t(i * dim));
      } catch (const Error& error) {
        errors[i] = error.what();
      }
    }
  });
  for (std::size_t i = 0; i < meshes.size(); ++i)
    if (!errors[i].empty()) throw Error(fmt::format("ShapeDatabase::add: shape '{}': {}", names[i], errors[i]));
  return insert(names, rows, labels);
}

std::vector<std::uint64_t> ShapeDatabase::add_descriptors(std::span<const std::string> names,
                                                          std::span<const float> descriptors,
                                                          std::span<const std::string> labels) {
  if (descriptors.size() != names.size() * dimension())
    throw Error(fmt::format("ShapeDatabase::add_descriptors: {} values for {} shapes of dimension {}",
                            descriptors.size(), names.size(), dimension()));
  return insert(names, descriptors, labels);
}

std::vector<std::uint64_t> ShapeDatabase::insert(std::span<const std::string> names, std::span<const float> rows,
                                                 std::span<const std::string> labels) {
  if (!labels.empty() && labels.size() != names.size())
    throw Error(fmt::format("ShapeDatabase: {} labels for {} shapes", labels.size(), names.size()));
  const std::vector<std::uint64_t> ids =
      tree_.insert(spatial::PointView<float>(rows.data(), names.size(), dimension()));
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (ids[i] != names_.size()) throw Error("ShapeDatabase: ids out of step with the names");
    names_.push_back(names[i]);
    labels_.push_back(labels.empty() ? std::string() : labels[i]);
  }
  return ids;
}

std::vector<ShapeMatch> ShapeDatabase::query(const TriMesh& mesh, std::size_t k, double eps) const {
  return query_descriptor(describe(mesh), k, eps);
}

std::vector<ShapeMatch> ShapeDatabase::query_descriptor(std::span<const float> descriptor, std::size_t k,
                                                        double eps) const {
  if (descriptor.size() != dimension())
    throw Error(fmt::format("ShapeDatabase::query: a descriptor of {} values, the database's have {}",
                            descriptor.size(), dimension()));
  if (!(eps >= 0) || !std::isfinite(eps)) throw Error(fmt::format("ShapeDatabase::query: eps must be >= 0, got {}", eps));
  std::vector<ShapeMatch> out;
  if (k == 0 || empty()) return out;
  for (const auto& n : tree_.query(descriptor, std::min(k, size()), eps))
    out.push_back({n.index, names_[n.index], labels_[n.index], std::sqrt(double(n.squared_distance))});
  return out;
}

ShapeDatabaseStats ShapeDatabase::stats() const {
  ShapeDatabaseStats s;
  s.shapes = size();
  s.dimension = dimension();
  std::set<std::string_view> distinct;
  for (const std::string& l : labels_)
    if (!l.empty()) distinct.insert(l);
  s.labels = distinct.size();
  const auto tree = tree_.stats();
  s.structures = tree.structure.structures;
  s.bytes = tree.bytes;
  for (std::size_t i = 0; i < size(); ++i) s.bytes += names_[i].size() + labels_[i].size();
  return s;
}

void ShapeDatabase::validate() const {
  tree_.validate();
  if (names_.size() != labels_.size() || tree_.size() != names_.size())
    throw Error(fmt::format("ShapeDatabase::validate: {} vectors, {} names, {} labels", tree_.size(), names_.size(),
                            labels_.size()));
  if (tree_.dim() != dimension_of(options_)) throw Error("ShapeDatabase::validate: vectors of the wrong dimension");
  for (std::uint64_t id = 0; id < size(); ++id)
    if (!tree_.contains(id)) throw Error(fmt::format("ShapeDatabase::validate: shape {} has no vector", id));
}

void ShapeDatabase::save(const std::filesystem::path& path) const {
  ArchiveWriter w(std::string(kShapeDatabaseArchiveKind), kShapeDatabaseArchiveVersion);
  std::vector<std::uint32_t> functions;
  for (ShapeFunction f : options_.functions) functions.push_back(std::uint32_t(f));
  const DistributionOptions& d = options_.distribution;
  w.add("functions", functions);
  w.add("weights", options_.weights);
  w.add_value("samples", std::uint64_t(d.samples));
  w.add_value("bins", std::uint64_t(d.bins));
  w.add_value("seed", d.seed);
  w.add_value("normalization", std::uint32_t(d.normalization));
  w.add_value("max_value", d.max_value);
  w.add_value("shapes", std::uint64_t(size()));
  std::vector<std::uint8_t> name_bytes, label_bytes;
  std::vector<std::uint64_t> name_offsets, label_offsets;
  add_strings(w, "names", names_, name_bytes, name_offsets);
  add_strings(w, "labels", labels_, label_bytes, label_offsets);
  tree_.add_sections(w, "tree.");
  w.write(path);
}

ShapeDatabase ShapeDatabase::load(const std::filesystem::path& path) {
  const Archive a = Archive::open(path, kShapeDatabaseArchiveKind, kShapeDatabaseArchiveVersion);
  DescriptorOptions o;
  o.functions.clear();
  for (std::uint32_t f : a.array<std::uint32_t>("functions")) {
    if (f > std::uint32_t(ShapeFunction::d4)) throw a.error(fmt::format("bad shape function {}", f));
    o.functions.push_back(ShapeFunction(f));
  }
  o.weights = a.array<double>("weights").to_vector();
  o.distribution.samples = std::size_t(a.value<std::uint64_t>("samples"));
  o.distribution.bins = std::size_t(a.value<std::uint64_t>("bins"));
  o.distribution.seed = a.value<std::uint64_t>("seed");
  const std::uint32_t normalization = a.value<std::uint32_t>("normalization");
  if (normalization > std::uint32_t(Normalization::none)) throw a.error("bad normalization");
  o.distribution.normalization = Normalization(normalization);
  o.distribution.max_value = a.value<double>("max_value");
  const std::uint64_t shapes = a.value<std::uint64_t>("shapes");
  if (shapes >= std::numeric_limits<std::uint32_t>::max()) throw a.error("too many shapes");
  std::optional<ShapeDatabase> db;
  a.check([&] { db.emplace(o); });
  db->names_ = read_strings(a, "names", std::size_t(shapes));
  db->labels_ = read_strings(a, "labels", std::size_t(shapes));
  db->tree_ = Tree::from_sections(a, "tree.");
  a.check([&] { db->validate(); });
  return std::move(*db);
}

}  // namespace geods::shape
