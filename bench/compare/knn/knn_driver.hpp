#pragma once
// The knn comparison: the same inputs, timing loop and checks for every library;
// each program only supplies an adapter (see compare_knn_*.cpp).
//
// Workload (anchors/WORKLOADS.md): a k-d tree over 1M float32 3D points with leaf size 10,
// then 100k queries with k = 10, one query at a time. Variants `uniform` and `clustered`
// (knn_<variant>_points.f32 / knn_<variant>_queries.f32). With --threads N > 1 the queries
// are split over N threads with tbb::parallel_for (each query still one at a time), and the
// build uses whatever parallelism the library has (nanoflann 1.4: none).
// Sanity ("ok"): 200 queries (every 500th) compared with brute force in double: the k
// distances match to 1e-5 (relative). "checksum": FNV-1a of every query's neighbour indices
// sorted ascending, so run.py can check that the libraries find the same neighbours.
//
// Variants `<input>_radius`: every query asks for all points within a fixed radius
// (kRadius: about 20 neighbours on average on each input), through the library's radius
// search with its results sorted by distance; "neighbours" is the mean count, "checksum"
// an order-independent hash of every query's set; ok: 200 sets equal brute force in double
// (points within 1e-5 relative of the radius may go either way). Variants `<input>_eps`:
// (1+eps) approximate k-NN with eps = kEps; ok: each of the k distances is within (1 + eps)
// of the exact one of its rank (no checksum: the libraries may return other neighbours).
// A library without these searches (no radius/knn_eps in its adapter) skips the variants.
//
// Adapter interface (struct Lib):
//   static constexpr const char* anchor;
//   struct Index;                                    the built structure
//   static std::unique_ptr<Index> build(const float* points, std::size_t n, std::size_t leaf_size);
//   static void knn(const Index&, const float* q, std::size_t k, std::uint32_t* indices, float* squared_distances);
//       the k nearest, ascending
//   optional: static void radius(const Index&, const float* q, float squared_radius, std::vector<std::uint32_t>& out);
//       every point within the radius (inclusive), as the library returns them (sorted by distance)
//   optional: static void knn_eps(const Index&, const float* q, std::size_t k, float eps, std::uint32_t*, float*);
#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common.hpp"

namespace compare::knn {

inline constexpr std::size_t kLeafSize = 10;
inline constexpr std::size_t kK = 10;
inline constexpr float kEps = 0.5f;
// About 20 neighbours per query: uniform in the unit cube, 4/3 pi r^3 n = 20 gives r = 0.0168;
// the clustered input (100 Gaussians of sigma 0.01) is denser where its queries are.
inline double radius_of(const std::string& input) { return input == "uniform" ? 0.0168 : 0.0027; }

template <class Lib>
concept HasRadius = requires(const typename Lib::Index& i, const float* q, std::vector<std::uint32_t>& out) {
  Lib::radius(i, q, 1.0f, out);
};
template <class Lib>
concept HasEps = requires(const typename Lib::Index& i, const float* q, std::uint32_t* ix, float* d) {
  Lib::knn_eps(i, q, std::size_t(1), 0.5f, ix, d);
};

// body(b, e) over the queries [0, m): one call on one thread, else split with tbb::parallel_for.
template <class Body>
void for_queries(const Args& args, std::size_t m, const Body& body) {
  if (args.threads == 1) {
    body(0, m);
  } else {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 256),
                      [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
  }
}

inline double squared_distance_d(const float* p, const float* q) {
  double s = 0;
  for (int a = 0; a < 3; ++a) s += (double(p[a]) - q[a]) * (double(p[a]) - q[a]);
  return s;
}
// An order-independent hash of a set of indices (splitmix64 of each, summed).
inline std::uint64_t set_hash(const std::vector<std::uint32_t>& ids) {
  std::uint64_t h = 0;
  for (std::uint32_t id : ids) {
    std::uint64_t z = id + 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    h += z ^ (z >> 31);
  }
  return h;
}

template <class Lib>
void run_radius(const Args& args, const std::string& input, const std::string& variant,
                const std::vector<float>& points, const std::vector<float>& queries, std::size_t n, std::size_t m) {
  std::unique_ptr<typename Lib::Index> index;
  const double build_s = median_time_s(args.reps, [&] {
    index.reset();
    index = Lib::build(points.data(), n, kLeafSize);
  });
  const double radius = radius_of(input);
  const float r2 = float(radius * radius);
  std::vector<std::uint64_t> hashes(m);
  std::vector<std::uint32_t> counts(m);
  auto query_all = [&] {
    auto body = [&](std::size_t b, std::size_t e) {
      thread_local std::vector<std::uint32_t> out;  // reused, as a caller would
      for (std::size_t i = b; i < e; ++i) {
        out.clear();
        Lib::radius(*index, &queries[3 * i], r2, out);
        counts[i] = std::uint32_t(out.size());
        hashes[i] = set_hash(out);
      }
    };
    for_queries(args, m, body);
  };
  const double query_s = median_time_s(args.reps, query_all);
  bool ok = true;
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < m && ok; i += 500) {
    const float* q = &queries[3 * i];
    out.clear();
    Lib::radius(*index, q, r2, out);
    std::vector<char> in(n, 0);
    for (std::uint32_t j : out) {
      if (j >= n || in[j]) ok = false;  // an index out of range or twice
      if (j < n) in[j] = 1;
    }
    for (std::size_t j = 0; j < n && ok; ++j) {
      const double d = std::sqrt(squared_distance_d(&points[3 * j], q));
      if (std::abs(d - radius) <= 1e-5 * radius) continue;  // on the boundary: either way
      if ((d < radius) != bool(in[j])) ok = false;
    }
  }
  std::uint64_t checksum = 0xcbf29ce484222325ULL;
  double total = 0;
  for (std::size_t i = 0; i < m; ++i) {
    checksum = fnv1a(&hashes[i], sizeof hashes[i], checksum);
    total += counts[i];
  }
  Record("knn", Lib::anchor, variant, args.threads)
      .timing(build_s, query_s, m, args.reps)
      .set("points", static_cast<unsigned long long>(n))
      .set("radius", radius)
      .set("neighbours", m ? total / double(m) : 0.0)
      .set("leaf_size", static_cast<unsigned long long>(kLeafSize))
      .set("checksum", hex64(checksum))
      .print(ok);
}

template <class Lib>
void run_variant(const Args& args, const std::string& variant) {
  const std::size_t cut = variant.find('_');
  const std::string input = variant.substr(0, cut), mode = cut == std::string::npos ? "" : variant.substr(cut + 1);
  if (mode == "radius" && !HasRadius<Lib>) return;
  if (mode == "eps" && !HasEps<Lib>) return;
  std::vector<float> points = read_raw<float>(args.path("knn_" + input + "_points.f32"));
  std::vector<float> queries = read_raw<float>(args.path("knn_" + input + "_queries.f32"));
  const std::size_t n = std::min(points.size() / 3, args.scaled(points.size() / 3));
  const std::size_t m = std::min(queries.size() / 3, args.scaled(queries.size() / 3));
  points.resize(3 * n);
  queries.resize(3 * m);
  if constexpr (HasRadius<Lib>)
    if (mode == "radius") return run_radius<Lib>(args, input, variant, points, queries, n, m);
  const float eps = mode == "eps" ? kEps : 0.0f;

  std::vector<std::uint32_t> indices(m * kK);
  std::vector<float> distances(m * kK);
  std::unique_ptr<typename Lib::Index> index;
  const double build_s = median_time_s(args.reps, [&] {
    index.reset();
    index = Lib::build(points.data(), n, kLeafSize);
  });
  auto query_all = [&] {
    auto body = [&](std::size_t b, std::size_t e) {
      if constexpr (HasEps<Lib>) {
        if (eps > 0) {
          for (std::size_t i = b; i < e; ++i)
            Lib::knn_eps(*index, &queries[3 * i], kK, eps, &indices[i * kK], &distances[i * kK]);
          return;
        }
      }
      for (std::size_t i = b; i < e; ++i) Lib::knn(*index, &queries[3 * i], kK, &indices[i * kK], &distances[i * kK]);
    };
    for_queries(args, m, body);
  };
  const double query_s = median_time_s(args.reps, query_all);

  bool ok = true;
  std::vector<double> brute(n);
  for (std::size_t i = 0; i < m; i += 500) {
    const float* q = &queries[3 * i];
    for (std::size_t j = 0; j < n; ++j) {
      double s = 0;
      for (int a = 0; a < 3; ++a) s += (double(points[3 * j + a]) - q[a]) * (double(points[3 * j + a]) - q[a]);
      brute[j] = s;
    }
    std::partial_sort(brute.begin(), brute.begin() + kK, brute.end());
    for (std::size_t r = 0; r < kK; ++r) {
      const std::uint32_t j = indices[i * kK + r];
      if (j >= n) {
        ok = false;
        break;
      }
      double s = 0;
      for (int a = 0; a < 3; ++a) s += (double(points[3 * j + a]) - q[a]) * (double(points[3 * j + a]) - q[a]);
      const double tolerance = 1e-5 * std::max(1.0, std::sqrt(brute[r]));
      if (eps > 0 ? std::sqrt(s) > (1 + eps) * std::sqrt(brute[r]) + tolerance
                  : std::abs(std::sqrt(s) - std::sqrt(brute[r])) > tolerance)
        ok = false;
    }
  }
  Record record("knn", Lib::anchor, variant, args.threads);
  record.timing(build_s, query_s, m, args.reps)
      .set("points", static_cast<unsigned long long>(n))
      .set("k", static_cast<unsigned long long>(kK))
      .set("leaf_size", static_cast<unsigned long long>(kLeafSize));
  if (eps > 0)
    record.set("eps", double(eps));
  else
    record.set("checksum", hex64(neighbour_checksum<kK>(indices.data(), m)));
  record.print(ok);
}

template <class Lib>
int run(int argc, char** argv) {
  return run_variants(argc, argv,
                      {"uniform", "clustered", "uniform_radius", "clustered_radius", "uniform_eps", "clustered_eps"},
                      run_variant<Lib>);
}

}  // namespace compare::knn
