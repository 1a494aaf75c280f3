// Inputs shared by the shape comparison programs, so geods and PCL get exactly the same meshes:
// tori of 1k..1M triangles for the descriptor time, the labelled BlendSwap-CC-0 furniture
// library of ../shared/data (175 Sweet Home 3D models) for retrieval quality, read by geods'
// collection reader (members geods cannot read are left out of both).
#pragma once
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "common.hpp"
#include "geods/core/tri_mesh.hpp"
#include "geods/shape/analytic_shapes.hpp"
#include "geods/shape/collection.hpp"
#include "geods/shape/retrieval.hpp"

namespace shape_bench {

/// Triangle counts of the descriptor-time variants: describe_1k ... describe_1m.
struct Size {
  const char* variant;
  int nu, nv;  // torus quads: 2 nu nv triangles
};
inline constexpr Size kSizes[] = {{"describe_1k", 25, 20}, {"describe_10k", 100, 50}, {"describe_100k", 250, 200},
                                  {"describe_1m", 1000, 500}};

inline geods::TriMesh torus(const Size& s) { return geods::shape::torus_mesh(2.0f, 0.7f, s.nu, s.nv); }

/// The subdivided bunnies of WORKLOADS.md (58,784 and 940,544 triangles): variants describe_bunny_100k, _1m.
inline constexpr std::pair<const char*, const char*> kBunnies[] = {{"describe_bunny_100k", "mesh_100k.ply"},
                                                                   {"describe_bunny_1m", "mesh_1m.ply"}};
inline geods::TriMesh workload_mesh(const compare::Args& args, const char* file) {
  const compare::PlyMesh ply = compare::read_ply(args.path(file));
  geods::TriMesh m;
  for (std::size_t i = 0; i < ply.vertices(); ++i) m.vertices.emplace_back(ply.xyz[3 * i], ply.xyz[3 * i + 1], ply.xyz[3 * i + 2]);
  for (std::size_t i = 0; i < ply.triangles(); ++i)
    m.triangles.push_back({std::uint32_t(ply.tris[3 * i]), std::uint32_t(ply.tris[3 * i + 1]), std::uint32_t(ply.tris[3 * i + 2])});
  return m;
}

/// Every mesh of the descriptor-time variants: (variant, mesh) for those --only selects.
inline std::vector<std::pair<std::string, geods::TriMesh>> describe_meshes(const compare::Args& args) {
  std::vector<std::pair<std::string, geods::TriMesh>> out;
  for (const Size& s : kSizes)
    if (args.wants(s.variant)) out.emplace_back(s.variant, torus(s));
  for (const auto& [variant, file] : kBunnies)
    if (args.wants(variant)) out.emplace_back(variant, workload_mesh(args, file));
  return out;
}

/// The labelled collection: $GEODS_SHAPE_DB, else ../shared/data/shape_db/BlendSwap-CC-0.sh3f
/// beside the checkout (or beside its worktree folder).
inline std::filesystem::path collection_path() {
  if (const char* env = std::getenv("GEODS_SHAPE_DB")) return env;
  namespace fs = std::filesystem;
  const fs::path repo = fs::path(GEODS_COMPARE_REPO);
  for (const fs::path& base : {repo.parent_path(), repo.parent_path().parent_path()}) {
    const fs::path p = base / "shared" / "data" / "shape_db" / "BlendSwap-CC-0.sh3f";
    if (fs::exists(p)) return p;
  }
  compare::die("BlendSwap-CC-0.sh3f not found (set GEODS_SHAPE_DB)");
}

struct Labelled {
  std::vector<std::string> names, labels;
  std::vector<geods::TriMesh> meshes;
};

/// Every readable model of the collection with its category (--scale keeps a prefix).
inline Labelled read_collection(const compare::Args& args) {
  const auto c = geods::shape::ShapeCollection::open(collection_path());
  Labelled out;
  const std::size_t n = std::min(c.size(), args.scaled(c.size()));
  for (std::size_t i = 0; i < n; ++i) {
    try {
      out.meshes.push_back(c.read(i));
      out.names.push_back(c.entries()[i].name);
      out.labels.push_back(c.entries()[i].label);
    } catch (const std::exception&) {  // unreadable by geods (2 of 175): left out for every library
    }
  }
  return out;
}

/// PSB measures (leave one out) of a ranking by `distance(i, j)` (brute force), with geods' scorer.
template <class Distance>
geods::shape::RetrievalScores score(const std::vector<std::string>& labels, std::size_t k, Distance distance) {
  geods::shape::RetrievalScores s;
  s.k = k;
  s.recall.resize(20);
  for (std::size_t l = 0; l < 20; ++l) s.recall[l] = double(l + 1) / 20;
  s.precision.assign(20, 0);
  const std::size_t n = labels.size();
  for (std::size_t q = 0; q < n; ++q) {
    std::size_t size = 0;
    for (const auto& l : labels) size += l == labels[q];
    if (size < 2) continue;
    std::vector<std::pair<double, std::size_t>> ranked;
    for (std::size_t j = 0; j < n; ++j)
      if (j != q) ranked.push_back({distance(q, j), j});
    std::sort(ranked.begin(), ranked.end());
    std::vector<bool> relevant;
    for (const auto& [d, j] : ranked) relevant.push_back(labels[j] == labels[q]);
    geods::shape::score_ranking(relevant, size, s);
    ++s.queries;
  }
  const double m = double(std::max<std::size_t>(1, s.queries));
  s.nn_rate /= m, s.precision_at_k /= m, s.first_tier /= m, s.second_tier /= m, s.mean_average_precision /= m;
  return s;
}

inline compare::Record& put_scores(compare::Record& r, const geods::shape::RetrievalScores& s) {
  return r.set("nn_rate", s.nn_rate)
      .set("precision_at_k", s.precision_at_k)
      .set("first_tier", s.first_tier)
      .set("second_tier", s.second_tier)
      .set("mean_average_precision", s.mean_average_precision)
      .set("queries", static_cast<unsigned long long>(s.queries));
}

}  // namespace shape_bench
