#include "geods/field/adf.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/core/grid3.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"
#include "geods/iso/marching_cubes.hpp"

namespace geods::field {
namespace {

constexpr char kKind[] = "field.Adf";
constexpr std::uint32_t kVersion = 1;

// The options and the root cube, one archive record.
struct Params {
  double error, band, padding;
  std::int32_t max_depth, checks;
  std::uint32_t sign, reserved;
  double origin[3];
  double size;
};

double physical_memory() { return double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE)); }

void check_options(const AdfOptions& o) {
  if (!std::isfinite(o.error) || !(o.error > 0)) throw Error(fmt::format("adf: the error must be finite and > 0, got {}", o.error));
  if (o.max_depth < 0 || o.max_depth > kAdfMaxDepth)
    throw Error(fmt::format("adf: max_depth must be in 0..{}, got {}", kAdfMaxDepth, o.max_depth));
  if (o.checks < 3 || o.checks > 9 || o.checks % 2 == 0)
    throw Error(fmt::format("adf: checks must be odd, 3 to 9, got {}", o.checks));
  if (!std::isfinite(o.padding) || !(o.padding >= 0) || o.padding > 100)
    throw Error(fmt::format("adf: padding must be in [0, 100], got {}", o.padding));
  if (std::isnan(o.band) || !(o.band > 0)) throw Error(fmt::format("adf: the band must be > 0, got {}", o.band));
  if (std::uint32_t(o.sign) > std::uint32_t(SignMethod::none)) throw Error("adf: unknown sign method");
}

float trilinear(const float* c, double x, double y, double z) {
  const double c00 = c[0] + (c[1] - c[0]) * x, c10 = c[2] + (c[3] - c[2]) * x;
  const double c01 = c[4] + (c[5] - c[4]) * x, c11 = c[6] + (c[7] - c[6]) * x;
  const double c0 = c00 + (c10 - c00) * y, c1 = c01 + (c11 - c01) * y;
  return float(c0 + (c1 - c0) * z);
}

// One cell of a level being built: its integer position at its level and its corner distances.
struct BuildCell {
  std::uint32_t x, y, z;
  float corners[8];
};

// What the evaluation of a cell decided.
struct CellResult {
  bool split = false;
  bool unresolved = false;
  std::uint32_t queries = 0;
  std::size_t signs = 0;
  float lattice[27];  // the distances at {0, 1/2, 1}^3 of the cell (x fastest): its children's corners
};

// A point whose exact (clamped) distance is known: a cell's corner or centre.
struct Known {
  Vec3d p;
  float d;
};

// The exact field as the ADF stores it: the distance clamped to the band.
// The closest point is searched unsigned, no farther than the distance a
// known point bounds (|d_k| + |p - p_k|); the sign is that of a known point k
// when the balls about p and k free of surface overlap along the segment
// between them (|d| + |d_k| > |p - p_k|: the segment meets no surface), and
// is only computed (winding number, or pseudonormal) near the surface.
class Exact {
 public:
  Exact(const MeshDistance& mesh, const AdfOptions& o, double size)
      : mesh_(mesh), sign_(o.sign), outer_(2 * o.band), slack_(1e-6 * size) {}

  // Distance at p clamped to twice the band, searching no farther than
  // `reach` beyond the band (default: to twice the band; a point farther
  // gets +-that limit, and `beyond` tells).
  float operator()(const Vec3d& p, std::span<const Known> known, std::size_t& windings, double reach = -1,
                   bool* beyond = nullptr) const {
    const bool banded = std::isfinite(outer_);
    const double limit = banded ? (reach < 0 ? outer_ : outer_ / 2 + reach) : std::numeric_limits<double>::infinity();
    double bound = limit;
    for (const Known& k : known)
      if (!banded || std::abs(k.d) < outer_) bound = std::min(bound, std::abs(double(k.d)) + (p - k.p).norm());
    const Vec3f pf = p.cast<float>();
    const bool bounded = bound < limit;
    MeshPointDistance r = mesh_.query(pf, SignMethod::none, float(bounded ? bound * (1 + 1e-5) + slack_ : limit));
    if (bounded && std::isinf(r.distance)) r = mesh_.query(pf, SignMethod::none, float(limit));
    const bool far = std::isinf(r.distance);
    if (beyond) *beyond = far;
    const double u = far ? limit : double(r.distance);  // a lower bound when far
    double sign = 1;
    if (sign_ != SignMethod::none) {
      bool found = false;
      for (const Known& k : known)
        if (k.d != 0 && u + std::abs(double(k.d)) > (p - k.p).norm() * (1 + 1e-5) + slack_) {
          sign = k.d < 0 ? -1 : 1;
          found = true;
          break;
        }
      if (!found) {
        ++windings;
        if (sign_ == SignMethod::pseudonormal && !far)
          sign = mesh_.inside_by_pseudonormal(pf, r) ? -1 : 1;
        else
          sign = mesh_.winding_number(pf) > 0.5 ? -1 : 1;
      }
    }
    const double d = sign * u;
    return float(banded ? std::clamp(d, -outer_, outer_) : d);
  }

 private:
  const MeshDistance& mesh_;
  SignMethod sign_;
  double outer_, slack_;
};

}  // namespace

Adf Adf::build(const TriMesh& mesh, const AdfOptions& options) {
  check_options(options);
  return build(mesh, MeshDistance::build(mesh), options);
}

Adf Adf::build(const TriMesh& source, const MeshDistance& mesh, const AdfOptions& options) {
  check_options(options);
  if (mesh.num_faces() == 0 || source.num_triangles() == 0) throw Error("adf: the mesh has no faces");
  const AABB3f box = source.bounds();
  if (box.empty() || !box.lo.allFinite() || !box.hi.allFinite()) throw Error("adf: the mesh's bounds are not finite");
  const double extent = box.extent().cast<double>().maxCoeff();
  if (!(extent > 0)) throw Error("adf: the mesh has no extent (all its vertices coincide)");

  Adf adf;
  adf.options_ = options;
  adf.size_ = extent * (1 + 2 * options.padding);
  adf.origin_ = (box.lo.cast<double>() + box.hi.cast<double>()) / 2 - Vec3d::Constant(adf.size_ / 2);
  if (!adf.origin_.allFinite() || !std::isfinite(adf.size_) ||
      !(adf.origin_ + Vec3d::Constant(adf.size_)).cast<float>().allFinite())
    throw Error("adf: the root cube reaches beyond float range");

  const Exact exact(mesh, options, adf.size_);
  const float band = std::isfinite(options.band) ? float(options.band) : std::numeric_limits<float>::infinity();
  auto clamp_band = [band](float v) { return std::clamp(v, -band, band); };
  const int n = options.checks, m = (n - 1) / 2;
  const float error = float(options.error);
  std::vector<std::uint32_t> nodes;
  std::vector<float> values;
  std::size_t queries = 0, unresolved = 0;

  std::vector<BuildCell> level(1), next;
  level[0] = {0, 0, 0, {}};
  std::size_t signs = 0;
  for (int c = 0; c < 8; ++c)
    level[0].corners[c] = exact(adf.origin_ + Vec3d(c & 1, (c >> 1) & 1, (c >> 2) & 1) * adf.size_, {}, signs);
  queries += 8;
  std::vector<CellResult> results;
  const double memory = physical_memory();

  for (int depth = 0; !level.empty(); ++depth) {
    const double side = adf.size_ / double(std::uint64_t(1) << depth), h = side / (n - 1);
    const double half_diagonal = side * std::sqrt(3.0) / 2;
    results.assign(level.size(), CellResult{});
    parallel_for_each_index(
        0, level.size(),
        [&](std::size_t i) {
          const BuildCell& cell = level[i];
          CellResult& r = results[i];
          const Vec3d lo = adf.origin_ + Vec3d(cell.x, cell.y, cell.z) * side;
          std::array<Known, 9> known;
          for (int c = 0; c < 8; ++c) known[c] = {lo + Vec3d(c & 1, (c >> 1) & 1, (c >> 2) & 1) * side, cell.corners[c]};
          // A cell wholly beyond the band holds the constant +-band: a leaf.
          bool beyond = false;
          const Vec3d mid = lo + Vec3d::Constant(side / 2);
          const float centre = exact(mid, std::span(known.data(), 8), r.signs, half_diagonal, &beyond);
          known[8] = {mid, centre};
          ++r.queries;
          if (beyond) return;
          const bool deepest = depth == options.max_depth;
          auto error_at = [&](int a, int b, int c, float& value) {
            if ((a == 0 || a == n - 1) && (b == 0 || b == n - 1) && (c == 0 || c == n - 1)) {
              value = cell.corners[(a ? 1 : 0) + (b ? 2 : 0) + (c ? 4 : 0)];
              return 0.0f;
            }
            if (a == m && b == m && c == m) {
              value = centre;
            } else {
              value = exact(lo + Vec3d(a, b, c) * h, known, r.signs);
              ++r.queries;
            }
            const double t = 1.0 / (n - 1);
            return std::abs(clamp_band(value) - clamp_band(trilinear(cell.corners, a * t, b * t, c * t)));
          };
          // First the points that are the children's corners, then the rest of the lattice.
          const int coarse[3] = {0, m, n - 1};
          bool over = false;
          for (int c = 0; c < 3; ++c)
            for (int b = 0; b < 3; ++b)
              for (int a = 0; a < 3; ++a)
                over |= error_at(coarse[a], coarse[b], coarse[c], r.lattice[a + 3 * b + 9 * c]) > error;
          for (int c = 0; c < n && !over; ++c)
            for (int b = 0; b < n && !over; ++b)
              for (int a = 0; a < n && !over; ++a) {
                if (a % m == 0 && b % m == 0 && c % m == 0) continue;  // done above
                float value;
                over = error_at(a, b, c, value) > error;
              }
          r.split = over && !deepest;
          r.unresolved = over && deepest;
        },
        16);

    // Number the level's nodes in order; split cells' children make the next level.
    std::size_t splits = 0;
    for (const CellResult& r : results) splits += r.split;
    const std::size_t leaves = values.size() / 8 + (level.size() - splits);
    const std::size_t total_nodes = nodes.size() + level.size() + 8 * splits;
    if (total_nodes >= kLeaf || leaves >= kLeaf)
      throw Error(fmt::format("adf: more than 2^31 cells at depth {}: a larger error or a smaller max_depth", depth + 1));
    const double bytes = double(total_nodes) * 4 + double(leaves) * 32 + double(8 * splits) * (sizeof(BuildCell) + sizeof(CellResult));
    if (memory > 0 && bytes > memory)
      throw Error(fmt::format("adf: depth {} needs {:.1f} GB, more than this machine's {:.1f} GB: a larger error or a "
                              "smaller max_depth",
                              depth + 1, bytes / 1e9, memory / 1e9));
    next.clear();
    next.reserve(8 * splits);
    std::size_t first_child = nodes.size() + level.size();
    for (std::size_t i = 0; i < level.size(); ++i) {
      const CellResult& r = results[i];
      queries += r.queries;
      unresolved += r.unresolved;
      signs += r.signs;
      if (!r.split) {
        nodes.push_back(kLeaf | std::uint32_t(values.size() / 8));
        values.insert(values.end(), level[i].corners, level[i].corners + 8);
        continue;
      }
      nodes.push_back(std::uint32_t(first_child));
      first_child += 8;
      const BuildCell& cell = level[i];
      for (int o = 0; o < 8; ++o) {
        const int ox = o & 1, oy = (o >> 1) & 1, oz = (o >> 2) & 1;
        BuildCell child{2 * cell.x + ox, 2 * cell.y + oy, 2 * cell.z + oz, {}};
        for (int c = 0; c < 8; ++c)
          child.corners[c] = r.lattice[(ox + (c & 1)) + 3 * (oy + ((c >> 1) & 1)) + 9 * (oz + ((c >> 2) & 1))];
        next.push_back(child);
      }
    }
    std::swap(level, next);
  }
  adf.nodes_ = FlatArray<std::uint32_t>(std::move(nodes));
  adf.values_ = FlatArray<float>(std::move(values));
  adf.stats_.exact_queries = queries;
  adf.stats_.unresolved = unresolved;
  adf.stats_.signs = signs;
  adf.finish_stats();
  return adf;
}

void Adf::finish_stats() {
  stats_.cells = nodes_.size();
  stats_.leaves = values_.size() / 8;
  // Levels are consecutive node ranges: the children of one level's inner nodes make the next.
  std::size_t begin = 0, end = nodes_.empty() ? 0 : 1, inner = 0, depth = 0;
  while (true) {
    const std::size_t inner_begin = inner;
    for (std::size_t i = begin; i < end; ++i) inner += !(nodes_[i] & kLeaf);
    if (inner == inner_begin) break;
    begin = end;
    end = 1 + 8 * inner;
    ++depth;
  }
  stats_.depth = depth;
  stats_.bytes = 4 * (nodes_.size() + values_.size());
  const double side = double(std::uint64_t(1) << depth) + 1;
  stats_.dense_bytes = std::size_t(4 * side * side * side);
}

void Adf::validate() const {
  check_options(options_);
  if (!origin_.allFinite() || !std::isfinite(size_) || !(size_ > 0)) throw Error("adf: the root cube is not finite");
  if (nodes_.empty() || nodes_.size() >= kLeaf) throw Error("adf: no nodes, or more than 2^31");
  std::size_t inner = 0, leaves = 0;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const std::uint32_t v = nodes_[i];
    if (v & kLeaf) {
      if ((v & ~kLeaf) != leaves) throw Error(fmt::format("adf: node {} names leaf {}, expected {}", i, v & ~kLeaf, leaves));
      ++leaves;
    } else {
      if (v != 1 + 8 * inner || std::size_t(v) + 8 > nodes_.size())
        throw Error(fmt::format("adf: node {} has its children at {}, expected {}", i, v, 1 + 8 * inner));
      ++inner;
    }
  }
  if (nodes_.size() != 1 + 8 * inner) throw Error("adf: the nodes are not an octree in level order");
  if (values_.size() != 8 * leaves)
    throw Error(fmt::format("adf: {} values for {} leaves, expected {}", values_.size(), leaves, 8 * leaves));
  const float outer = std::isfinite(options_.band) ? float(2 * options_.band) : std::numeric_limits<float>::max();
  for (std::size_t i = 0; i < values_.size(); ++i)
    if (!(std::abs(values_[i]) <= outer)) throw Error(fmt::format("adf: value {} is {} (not finite or beyond the band)", i, values_[i]));
  // The depth (levels are consecutive node ranges, see finish_stats).
  std::size_t begin = 0, end = 1, counted = 0;
  for (int depth = 0;; ++depth) {
    std::size_t level_inner = 0;
    for (std::size_t i = begin; i < end; ++i) level_inner += !(nodes_[i] & kLeaf);
    if (level_inner == 0) break;
    if (depth + 1 > options_.max_depth) throw Error(fmt::format("adf: cells deeper than max_depth {}", options_.max_depth));
    counted += level_inner;
    begin = end;
    end = 1 + 8 * counted;
  }
}

AdfSample Adf::sample(const Vec3f& p) const {
  if (!p.allFinite()) throw Error("adf: a query point is not finite");
  Vec3d u = (p.cast<double>() - origin_) / size_;
  const Vec3d inside = u.cwiseMax(0.0).cwiseMin(1.0);
  const Vec3d outside = (u - inside) * size_;  // p - (nearest point of the cube)
  u = inside;
  std::uint32_t node = nodes_[0];
  double side = size_;
  while (!(node & kLeaf)) {
    std::uint32_t child = 0;
    for (int a = 0; a < 3; ++a)
      if (u[a] >= 0.5) child |= 1u << a, u[a] = 2 * u[a] - 1;
      else u[a] = 2 * u[a];
    node = nodes_[node + child];
    side /= 2;
  }
  const float* c = &values_[std::size_t(node & ~kLeaf) * 8];
  AdfSample s;
  s.distance = trilinear(c, u.x(), u.y(), u.z());
  // The derivatives of the trilinear interpolation along x, y, z.
  const double x = u.x(), y = u.y(), z = u.z();
  const double dx = ((c[1] - c[0]) * (1 - y) + (c[3] - c[2]) * y) * (1 - z) + ((c[5] - c[4]) * (1 - y) + (c[7] - c[6]) * y) * z;
  const double dy = ((c[2] - c[0]) * (1 - x) + (c[3] - c[1]) * x) * (1 - z) + ((c[6] - c[4]) * (1 - x) + (c[7] - c[5]) * x) * z;
  const double dz = ((c[4] - c[0]) * (1 - x) + (c[5] - c[1]) * x) * (1 - y) + ((c[6] - c[2]) * (1 - x) + (c[7] - c[3]) * x) * y;
  Vec3d g = Vec3d(dx, dy, dz) / side;
  const double away = outside.norm();
  if (away > 0) {
    s.distance = float(double(s.distance) + away);
    for (int a = 0; a < 3; ++a)
      if (outside[a] != 0) g[a] = outside[a] / away;
  }
  s.gradient = g.cast<float>();
  if (std::isfinite(options_.band))
    s.distance = std::clamp(s.distance, -float(options_.band), float(options_.band));
  return s;
}

Vec3f Adf::closest_point(const Vec3f& p) const {
  const AdfSample s = sample(p);
  const float norm = s.gradient.norm();
  if (!(norm > 0)) return p;
  return p - s.distance * s.gradient / norm;
}

TriMesh Adf::isosurface(double offset, std::size_t res) const {
  if (!std::isfinite(offset)) throw Error("adf isosurface: the offset is not finite");
  if (std::isfinite(options_.band) && !(std::abs(offset) < options_.band))
    throw Error(fmt::format("adf isosurface: offset {} is outside the band {}", offset, options_.band));
  if (res == 0) res = (std::size_t(1) << std::min<std::size_t>(stats_.depth, 8)) + 1;
  if (res < 2) throw Error("adf isosurface: res must be >= 2");
  const double bytes = double(res) * double(res) * double(res) * 4;
  const double memory = physical_memory();
  if (res > (std::size_t(1) << 21) || (memory > 0 && bytes > memory / 2))
    throw Error(fmt::format("adf isosurface: {}^3 samples need {:.1f} GB, more than half this machine's {:.1f} GB", res,
                            bytes / 1e9, memory / 1e9));
  Grid3<float> grid(res, res, res);
  grid.origin = origin_.cast<float>();
  grid.spacing = Vec3f::Constant(float(size_ / double(res - 1)));
  // Marching cubes puts inside at samples >= iso: the negated distance, inside the offset surface.
  parallel_for_each_index(
      0, res * res,
      [&](std::size_t kj) {
        const std::size_t k = kj / res, j = kj % res;
        for (std::size_t i = 0; i < res; ++i) {
          const Vec3d p = origin_ + Vec3d(double(i), double(j), double(k)) * (size_ / double(res - 1));
          grid(i, j, k) = -distance(p.cast<float>());
        }
      },
      4);
  return iso::isosurface(grid, -offset);
}

void Adf::save(const std::filesystem::path& path) const {
  Params p{options_.error, options_.band, options_.padding, options_.max_depth, options_.checks,
           std::uint32_t(options_.sign), 0, {origin_.x(), origin_.y(), origin_.z()}, size_};
  ArchiveWriter w(kKind, kVersion);
  w.add_value("params", p);
  w.add_value("stats", stats_);
  w.add("nodes", nodes_);
  w.add("values", values_);
  w.write(path);
}

Adf Adf::load(const std::filesystem::path& path, Archive::Verify verify) {
  const Archive a = Archive::open(path, kKind, kVersion, verify);
  const Params p = a.value<Params>("params");
  Adf adf;
  adf.options_.error = p.error;
  adf.options_.band = p.band;
  adf.options_.padding = p.padding;
  adf.options_.max_depth = p.max_depth;
  adf.options_.checks = p.checks;
  if (p.sign > std::uint32_t(SignMethod::none)) throw a.error("unknown sign method");
  adf.options_.sign = SignMethod(p.sign);
  adf.origin_ = Vec3d(p.origin[0], p.origin[1], p.origin[2]);
  adf.size_ = p.size;
  adf.nodes_ = a.array<std::uint32_t>("nodes");
  adf.values_ = a.array<float>("values");
  const AdfStats stored = a.value<AdfStats>("stats");
  a.check([&] { adf.validate(); });
  adf.stats_.exact_queries = stored.exact_queries;
  adf.stats_.unresolved = stored.unresolved;
  adf.stats_.signs = stored.signs;
  adf.finish_stats();
  return adf;
}

AdfError measure_adf_error(const Adf& adf, const TriMesh& source, const MeshDistance& mesh, std::size_t samples,
                           std::uint64_t seed) {
  if (source.num_triangles() == 0) throw Error("adf error: the mesh has no faces");
  Rng rng(seed);
  const double finest = adf.size() / double(std::uint64_t(1) << adf.stats().depth);
  const Vec3d lo = adf.origin(), hi = lo + Vec3d::Constant(adf.size());
  std::vector<Vec3f> points(samples);
  for (std::size_t i = 0; i < samples; ++i) {
    Vec3d p;
    if (i % 2 == 0) {
      p = Vec3d(rng.uniform(), rng.uniform(), rng.uniform());
      p = lo + p * adf.size();
    } else {
      const auto& t = source.triangles[rng.below(source.num_triangles())];
      double a = rng.uniform(), b = rng.uniform();
      if (a + b > 1) a = 1 - a, b = 1 - b;
      const Vec3d v0 = source.vertices[t[0]].cast<double>(), v1 = source.vertices[t[1]].cast<double>(),
                  v2 = source.vertices[t[2]].cast<double>();
      Vec3d dir(rng.normal(), rng.normal(), rng.normal());
      if (dir.norm() > 0) dir.normalize();
      p = v0 + a * (v1 - v0) + b * (v2 - v0) + dir * rng.uniform(0, 8 * finest);
    }
    points[i] = p.cwiseMax(lo).cwiseMin(hi).cast<float>();
  }
  std::vector<double> errors(samples);
  const double band = adf.options().band;
  parallel_for_each_index(
      0, samples,
      [&](std::size_t i) {
        double d = mesh.query(points[i], adf.options().sign).distance;
        if (std::isfinite(band)) d = std::clamp(d, -band, band);
        errors[i] = std::abs(double(adf.distance(points[i])) - d);
      },
      64);
  AdfError e;
  e.samples = samples;
  for (const double x : errors) e.max_error = std::max(e.max_error, x), e.mean_error += x;
  if (samples) e.mean_error /= double(samples);
  return e;
}

}  // namespace geods::field
