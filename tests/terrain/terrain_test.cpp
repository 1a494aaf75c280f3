// The 4-8 terrain hierarchy against independent oracles: the meshes tile the
// field's domain (areas, edges shared by two triangles, no T-vertices), every
// sample is within the error bound (point location by brute force), the strip
// and the triangle list are the same mesh, the layout's slots against the
// DAG built by explicit bisection, the mapped file against the in-memory build.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <random>
#include <set>

#include "common/data_files.hpp"
#include "common/simd_level_guard.hpp"
#include "geods/core/error.hpp"
#include "geods/core/simd_level.hpp"
#include "geods/io/npy.hpp"
#include "geods/terrain/terrain.hpp"

namespace geods::terrain {
namespace {

HeightField field_of(std::size_t w, std::size_t h, auto&& fn) {
  HeightField f;
  f.width = w;
  f.height = h;
  f.heights.resize(w * h);
  for (std::size_t y = 0; y < h; ++y)
    for (std::size_t x = 0; x < w; ++x) f.heights[y * w + x] = float(fn(double(x), double(y)));
  return f;
}

HeightField noise(std::size_t w, std::size_t h, unsigned seed, double amplitude = 10) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  return field_of(w, h, [&](double x, double y) { return 3 * std::sin(x * 0.3) * std::cos(y * 0.2) + u(rng); });
}

HeightField real_field() {
  const io::NpyArray a = io::read_npy(test::data_path("jacksboro_dem.npy"));
  const std::vector<double> v = a.to_vector<double>();
  // A 70 x 45 corner keeps the oracle fast (it is quadratic).
  return field_of(70, 45, [&](double x, double y) { return v[std::size_t(y) * a.shape[1] + std::size_t(x)]; });
}

using Tri = std::array<std::uint32_t, 3>;

Refinement by_error(double e) {
  Refinement r;
  r.max_error = e;
  return r;
}

std::int64_t cross2(const std::array<std::uint32_t, 2>& a, const std::array<std::uint32_t, 2>& b,
                    const std::array<std::uint32_t, 2>& c) {
  return (std::int64_t(b[0]) - a[0]) * (std::int64_t(c[1]) - a[1]) -
         (std::int64_t(b[1]) - a[1]) * (std::int64_t(c[0]) - a[0]);
}

// The mesh tiles [0, W-1] x [0, H-1]: counter-clockwise triangles whose doubled
// areas add up, every edge used once in each direction inside and once on the
// border, and no vertex inside an edge (no T-vertices).
void expect_tiling(const TerrainMesh& m, std::size_t W, std::size_t H) {
  ASSERT_FALSE(m.triangles.empty());
  std::int64_t area2 = 0;
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  std::set<std::pair<std::uint32_t, std::uint32_t>> positions;
  for (const auto& s : m.samples) {
    ASSERT_LT(s[0], W);
    ASSERT_LT(s[1], H);
    positions.insert({s[0], s[1]});
  }
  ASSERT_EQ(positions.size(), m.samples.size()) << "two vertices at one sample";
  for (const Tri& t : m.triangles) {
    const std::int64_t c = cross2(m.samples[t[0]], m.samples[t[1]], m.samples[t[2]]);
    ASSERT_GT(c, 0) << "a triangle that is not counter-clockwise";
    area2 += c;
    for (int e = 0; e < 3; ++e) ++directed[{t[e], t[(e + 1) % 3]}];
  }
  EXPECT_EQ(area2, 2 * std::int64_t(W - 1) * std::int64_t(H - 1));
  for (const auto& [edge, count] : directed) {
    ASSERT_EQ(count, 1) << "an edge used twice in one direction (overlap)";
    const auto a = m.samples[edge.first], b = m.samples[edge.second];
    if (!directed.count({edge.second, edge.first})) {
      // A border edge: on the domain's border.
      const bool on_border = (a[0] == b[0] && (a[0] == 0 || a[0] == W - 1)) ||
                             (a[1] == b[1] && (a[1] == 0 || a[1] == H - 1));
      ASSERT_TRUE(on_border) << "an edge with one triangle inside the domain (a crack)";
    }
    // No vertex strictly inside the edge.
    const std::int64_t dx = std::int64_t(b[0]) - a[0], dy = std::int64_t(b[1]) - a[1];
    const std::int64_t g = std::gcd(std::abs(dx), std::abs(dy));
    for (std::int64_t k = 1; k < g; ++k)
      ASSERT_FALSE(positions.count({std::uint32_t(a[0] + dx / g * k), std::uint32_t(a[1] + dy / g * k)}))
          << "a T-vertex";
  }
}

// The largest vertical distance from the samples to the mesh, by locating each
// sample in a triangle by brute force (exact integer orientation tests).
double brute_force_error(const TerrainMesh& m, const Terrain& t) {
  double worst = 0;
  for (std::uint32_t y = 0; y < t.height(); ++y)
    for (std::uint32_t x = 0; x < t.width(); ++x) {
      const std::array<std::uint32_t, 2> p{x, y};
      bool found = false;
      for (const Tri& tri : m.triangles) {
        const auto &a = m.samples[tri[0]], &b = m.samples[tri[1]], &c = m.samples[tri[2]];
        const std::int64_t wa = cross2(b, c, p), wb = cross2(c, a, p), wc = cross2(a, b, p);
        if (wa < 0 || wb < 0 || wc < 0) continue;
        const double sum = double(wa + wb + wc);
        const double z = (wa * double(m.vertices[tri[0]].z()) + wb * double(m.vertices[tri[1]].z()) +
                          wc * double(m.vertices[tri[2]].z())) / sum;
        worst = std::max(worst, std::abs(z - double(t.sample(x, y))));
        found = true;
        break;
      }
      EXPECT_TRUE(found) << "sample " << x << "," << y << " in no triangle";
    }
  return worst;
}

std::multiset<std::array<std::uint32_t, 3>> sorted(const std::vector<Tri>& tris) {
  std::multiset<std::array<std::uint32_t, 3>> s;
  for (Tri t : tris) {
    std::sort(t.begin(), t.end());
    s.insert(t);
  }
  return s;
}

// The strip's non-degenerate triangles (with their winding by parity).
std::vector<Tri> strip_triangles(const TerrainMesh& m, bool* consistent) {
  std::vector<Tri> out;
  *consistent = true;
  for (std::size_t k = 0; k + 2 < m.strip.size(); ++k) {
    Tri t{m.strip[k], m.strip[k + 1], m.strip[k + 2]};
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    if (k % 2) std::swap(t[0], t[1]);
    const std::int64_t c = cross2(m.samples[t[0]], m.samples[t[1]], m.samples[t[2]]);
    if (c == 0) continue;
    if (c < 0) *consistent = false;
    out.push_back(t);
  }
  return out;
}

// The max-error mesh by explicit longest-edge bisection, independent of the
// library's strip recursion: the 4 triangles around the centre of the padded
// grid, a triangle split while its hypotenuse's midpoint is a sample whose
// nested error exceeds e (the padding's is infinite); the triangles inside
// the field, as sorted sample-coordinate triples.
std::multiset<std::array<std::array<std::uint32_t, 2>, 3>> bisection_mesh(const Terrain& t, double e) {
  const std::int64_t N = std::int64_t(t.layout().n()) - 1, c = N / 2;
  using P = std::array<std::int64_t, 2>;
  struct T {
    P apex, l, r;
  };
  std::vector<T> stack = {{{c, c}, {0, 0}, {N, 0}}, {{c, c}, {N, 0}, {N, N}}, {{c, c}, {N, N}, {0, N}}, {{c, c}, {0, N}, {0, 0}}};
  std::multiset<std::array<std::array<std::uint32_t, 2>, 3>> out;
  while (!stack.empty()) {
    const T tri = stack.back();
    stack.pop_back();
    const std::int64_t mx = tri.l[0] + tri.r[0], my = tri.l[1] + tri.r[1];
    if (mx % 2 == 0 && my % 2 == 0) {
      const float err = t.record(std::uint32_t(mx / 2), std::uint32_t(my / 2)).error;
      if (std::isinf(err) || double(err) > e) {
        const P m{mx / 2, my / 2};
        stack.push_back({m, tri.apex, tri.l});
        stack.push_back({m, tri.r, tri.apex});
        continue;
      }
    }
    std::array<std::array<std::uint32_t, 2>, 3> v;
    bool inside = true;
    for (int k = 0; k < 3; ++k) {
      const P& p = k == 0 ? tri.apex : k == 1 ? tri.l : tri.r;
      inside = inside && p[0] < std::int64_t(t.width()) && p[1] < std::int64_t(t.height());
      v[k] = {std::uint32_t(p[0]), std::uint32_t(p[1])};
    }
    std::sort(v.begin(), v.end());
    if (inside) out.insert(v);
  }
  return out;
}

std::multiset<std::array<std::array<std::uint32_t, 2>, 3>> mesh_by_samples(const TerrainMesh& m) {
  std::multiset<std::array<std::array<std::uint32_t, 2>, 3>> out;
  for (const Tri& tri : m.triangles) {
    std::array<std::array<std::uint32_t, 2>, 3> v{m.samples[tri[0]], m.samples[tri[1]], m.samples[tri[2]]};
    std::sort(v.begin(), v.end());
    out.insert(v);
  }
  return out;
}

void expect_valid(const Terrain& t, const TerrainMesh& m, std::optional<double> bound) {
  expect_tiling(m, t.width(), t.height());
  bool consistent = false;
  EXPECT_EQ(sorted(strip_triangles(m, &consistent)), sorted(m.triangles)) << "strip and triangle list differ";
  EXPECT_TRUE(consistent) << "the strip's winding is not counter-clockwise throughout";
  const double brute = brute_force_error(m, t);
  EXPECT_NEAR(t.measure_error(m), brute, 1e-3 * (1 + brute));
  if (bound) {
    EXPECT_LE(brute, *bound + 1e-4 * (1 + *bound));
  }
}

TEST(Terrain, MaxErrorMeshesTileTheDomainWithinTheBound) {
  const std::vector<std::pair<std::string, HeightField>> fields = {
      {"noise 17x17", noise(17, 17, 1)},
      {"noise 23x11", noise(23, 11, 2)},
      {"spikes", field_of(33, 33, [](double x, double y) { return (int(x) % 7 == 3 && int(y) % 5 == 1) ? 100.0 : 0.0; })},
      {"cliff", field_of(30, 33, [](double x, double y) { return x + 0.3 * y > 14 ? 50.0 : 0.0; })},
      {"constant", field_of(9, 9, [](double, double) { return 4.0; })},
      {"2x2", field_of(2, 2, [](double x, double y) { return x * 3 + y; })},
      {"real", real_field()},
  };
  for (const auto& [name, f] : fields) {
    SCOPED_TRACE(name);
    const Terrain t(f);
    for (const double e : {0.0, 0.5, 3.0, 40.0}) {
      SCOPED_TRACE(e);
      const TerrainMesh m = t.refine(by_error(e));
      expect_valid(t, m, e);
      EXPECT_EQ(mesh_by_samples(m), bisection_mesh(t, e)) << "not the mesh of longest-edge bisection";
    }
    // Error 0 keeps every sample that is off the interpolating planes; a huge
    // error gives the coarsest mesh (4 triangles around the centre on a 2^k+1 field).
    EXPECT_LE(t.refine(by_error(1e30)).triangles.size(), t.refine(by_error(0.0)).triangles.size());
  }
  const Terrain flat(field_of(17, 17, [](double x, double y) { return 2 * x - y; }));
  EXPECT_EQ(flat.refine(by_error(0.0)).triangles.size(), 4u);  // a plane needs no refinement
}

TEST(Terrain, NestedErrorsAndSpheresOverTheBruteForceDag) {
  // The DAG by explicit longest-edge bisection of the 4 triangles around the
  // centre: parent = the apex of a triangle, child = its split vertex.
  const HeightField f = noise(33, 33, 7);
  for (const Layout layout : {Layout::interleaved, Layout::matrix}) {
    const Terrain t(f, {.z_scale = 2, .layout = layout});
    const std::int64_t N = 32, c = 16;
    std::set<std::pair<std::pair<int, int>, std::pair<int, int>>> edges;
    struct T {
      std::array<int, 2> apex, l, r;
    };
    std::vector<T> stack;
    for (const auto& [l, r] : std::vector<std::pair<std::array<int, 2>, std::array<int, 2>>>{
             {{0, 0}, {32, 0}}, {{32, 0}, {32, 32}}, {{32, 32}, {0, 32}}, {{0, 32}, {0, 0}}})
      stack.push_back({{int(c), int(c)}, l, r});
    std::map<std::pair<int, int>, int> parents;
    while (!stack.empty()) {
      const T tri = stack.back();
      stack.pop_back();
      if ((tri.l[0] + tri.r[0]) % 2 || (tri.l[1] + tri.r[1]) % 2) continue;
      const std::array<int, 2> m{(tri.l[0] + tri.r[0]) / 2, (tri.l[1] + tri.r[1]) / 2};
      if (edges.insert({{tri.apex[0], tri.apex[1]}, {m[0], m[1]}}).second) ++parents[{m[0], m[1]}];
      stack.push_back({m, tri.l, tri.apex});
      stack.push_back({m, tri.apex, tri.r});
    }
    std::size_t checked = 0;
    for (const auto& [p, ch] : edges) {
      const VertexRecord& a = t.record(p.first, p.second);
      const VertexRecord& b = t.record(ch.first, ch.second);
      if (!(p.first == c && p.second == c)) {
        EXPECT_GE(a.error, b.error);
      }
      const double dx = p.first - ch.first, dy = p.second - ch.second, dz = double(a.z) - b.z;
      EXPECT_GE(double(a.radius), std::sqrt(dx * dx + dy * dy + dz * dz) + b.radius - 1e-9);
      ++checked;
    }
    EXPECT_GT(checked, 1000u);
    // Two parents inside, one on the border.
    for (const auto& [v, count] : parents) {
      const bool border = v.first == 0 || v.second == 0 || v.first == N || v.second == N;
      EXPECT_EQ(count, border ? 1 : 2) << v.first << "," << v.second;
    }
    EXPECT_EQ(parents.size(), std::size_t(33 * 33 - 5));
    EXPECT_FLOAT_EQ(t.sample(3, 4), 2 * f(3, 4));
  }
}

// The largest |sample - plane| over the samples of the closed triangle (a, b, c),
// by brute force: every sample of the bounding box located by exact integer
// orientation tests, the plane by barycentric weights.
double triangle_error_brute(const Terrain& t, std::array<std::int64_t, 2> a, std::array<std::int64_t, 2> b,
                            std::array<std::int64_t, 2> c) {
  auto orient = [](auto p, auto q, auto r) { return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]); };
  if (orient(a, b, c) < 0) std::swap(b, c);
  const double area = double(orient(a, b, c));
  auto h = [&](auto p) { return double(t.sample(std::uint32_t(p[0]), std::uint32_t(p[1]))); };
  double worst = 0;
  for (std::int64_t y = std::min({a[1], b[1], c[1]}); y <= std::max({a[1], b[1], c[1]}); ++y)
    for (std::int64_t x = std::min({a[0], b[0], c[0]}); x <= std::max({a[0], b[0], c[0]}); ++x) {
      const std::array<std::int64_t, 2> p{x, y};
      const std::int64_t wa = orient(b, c, p), wb = orient(c, a, p), wc = orient(a, b, p);
      if (wa < 0 || wb < 0 || wc < 0) continue;
      const double plane = (double(wa) * h(a) + double(wb) * h(b) + double(wc) * h(c)) / area;
      worst = std::max(worst, std::abs(h(p) - plane));
    }
  return worst;
}

TEST(Terrain, NestedErrorsEqualTheBruteForceErrorsOverTheDag) {
  // Own error of a split vertex = the largest error of the triangles it splits
  // (infinite when one leaves the field), nested over its descendants in the
  // DAG of explicit longest-edge bisection.
  const std::vector<std::pair<std::string, HeightField>> fields = {
      {"noise 33x33", noise(33, 33, 11)},
      {"noise 23x11 (padded)", noise(23, 11, 12, 1000)},
      {"spikes", field_of(33, 33, [](double x, double y) { return (int(x) % 7 == 3 && int(y) % 5 == 1) ? 100.0 : 0.0; })},
      {"real 70x45 (padded)", real_field()},
  };
  for (const auto& [name, f] : fields) {
    SCOPED_TRACE(name);
    const Terrain t(f, {.z_scale = 1.5});
    const std::int64_t N = std::int64_t(t.layout().n()) - 1, c = N / 2, n = N + 1;
    using P = std::array<std::int64_t, 2>;
    struct T {
      P apex, l, r;
    };
    std::vector<T> stack = {{{c, c}, {0, 0}, {N, 0}}, {{c, c}, {N, 0}, {N, N}}, {{c, c}, {N, N}, {0, N}}, {{c, c}, {0, N}, {0, 0}}};
    std::vector<double> nested(std::size_t(n * n), 0.0);
    std::set<std::pair<std::int64_t, std::int64_t>> edges;  // (parent, child) as y n + x
    auto inside = [&](P p) { return p[0] < std::int64_t(t.width()) && p[1] < std::int64_t(t.height()); };
    while (!stack.empty()) {
      const T tri = stack.back();
      stack.pop_back();
      if ((tri.l[0] + tri.r[0]) % 2 || (tri.l[1] + tri.r[1]) % 2) continue;
      const P m{(tri.l[0] + tri.r[0]) / 2, (tri.l[1] + tri.r[1]) / 2};
      double& own = nested[std::size_t(m[1] * n + m[0])];
      own = std::max(own, inside(tri.apex) && inside(tri.l) && inside(tri.r)
                              ? triangle_error_brute(t, tri.l, tri.r, tri.apex)
                              : std::numeric_limits<double>::infinity());
      edges.insert({tri.apex[1] * n + tri.apex[0], m[1] * n + m[0]});
      stack.push_back({m, tri.l, tri.apex});
      stack.push_back({m, tri.apex, tri.r});
    }
    for (bool changed = true; changed;) {  // nest to a fixed point
      changed = false;
      for (const auto& [p, ch] : edges)
        if (nested[std::size_t(ch)] > nested[std::size_t(p)]) nested[std::size_t(p)] = nested[std::size_t(ch)], changed = true;
    }
    std::size_t infinite = 0;
    for (std::int64_t y = 0; y <= N; ++y)
      for (std::int64_t x = 0; x <= N; ++x) {
        const double want = nested[std::size_t(y * n + x)], got = t.record(std::uint32_t(x), std::uint32_t(y)).error;
        if (std::isinf(want)) {
          ASSERT_TRUE(std::isinf(got)) << x << "," << y;
          ++infinite;
        } else {
          ASSERT_GE(got, want * (1 - 1e-12)) << x << "," << y << ": not a bound";
          ASSERT_LE(got, want * (1 + 1e-6) + 1e-9) << x << "," << y << ": not tight";
        }
      }
    EXPECT_EQ(infinite > 0, t.width() != std::uint64_t(n) || t.height() != std::uint64_t(n));
  }
}

TEST(Terrain, InterleavedLayoutSlotsAgainstBruteForce) {
  for (std::uint32_t K = 1; K <= 7; ++K) {
    SCOPED_TRACE(K);
    const LayoutIndex li(Layout::interleaved, K);
    const std::uint32_t n = (1u << K) + 1;
    std::set<std::uint64_t> used;
    for (std::uint32_t y = 0; y < n; ++y)
      for (std::uint32_t x = 0; x < n; ++x) {
        const std::uint64_t s = li.slot(x, y);
        ASSERT_LT(s, li.slots());
        ASSERT_TRUE(used.insert(s).second) << "slot " << s << " twice (" << x << "," << y << ")";
      }
    const double unused = 1.0 - double(n) * n / double(li.slots());
    EXPECT_LE(unused, 0.33);
    if (K >= 4) {
      EXPECT_GE(unused, 0.15);
    }
    // Blue quadtree: the quadtree children (x +- s/2, y), (x, y +- s/2) of a blue
    // vertex of spacing s are slots 4 i + {0..3} of the next level.
    for (std::uint32_t t = 1; t < K; ++t) {
      const std::int64_t s = std::int64_t(1) << t, h = s / 2;
      for (std::int64_t y = 0; y < n; y += s)
        for (std::int64_t x = 0; x < n; x += s) {
          if (((x / s) + (y / s)) % 2 == 0) continue;  // not blue
          if ((x == 0 || x == n - 1) && (y == 0 || y == n - 1)) continue;
          const std::uint64_t i = li.slot(std::uint32_t(x), std::uint32_t(y)) - li.level_base(t);
          for (const auto& [cx, cy] : {std::pair{x - h, y}, std::pair{x + h, y}, std::pair{x, y - h}, std::pair{x, y + h}}) {
            if (cx < 0 || cy < 0 || cx >= n || cy >= n) continue;
            const std::uint64_t j = li.slot(std::uint32_t(cx), std::uint32_t(cy)) - li.level_base(t - 1);
            EXPECT_EQ(j / 4, i);
          }
        }
    }
  }
  const LayoutIndex m(Layout::matrix, 3);
  EXPECT_EQ(m.slots(), 81u);
  EXPECT_EQ(m.slot(2, 3), 29u);
}

TEST(Terrain, LayoutsGiveTheSameMeshes) {
  const HeightField f = noise(40, 27, 3);
  const Terrain a(f, {.layout = Layout::interleaved}), b(f, {.layout = Layout::matrix});
  for (const double e : {0.5, 4.0}) {
    const TerrainMesh ma = a.refine(by_error(e)), mb = b.refine(by_error(e));
    EXPECT_EQ(ma.strip, mb.strip);
    EXPECT_EQ(ma.triangles, mb.triangles);
  }
  EXPECT_LE(a.stats().unused_slots_pct, 33.0);
  EXPECT_EQ(b.stats().unused_slots, 0u);
}

TEST(Terrain, ViewDependentMeshesAreCrackFreeAndFinerNearTheEye) {
  const HeightField f = field_of(65, 65, [](double x, double y) { return 4 * std::sin(x * 0.4) * std::sin(y * 0.3) + 0.05 * x * y; });
  const Terrain t(f);
  Refinement r;
  TerrainView v;
  v.camera.eye = Vec3f(32, -5, 12);
  v.camera.target = Vec3f(32, 40, 0);
  v.camera.up = Vec3f(0, 0, 1);
  v.camera.vertical_fov_deg = 50;
  v.width = 320;
  v.height = 240;
  r.view = v;
  std::size_t previous = 0;
  for (const double tau : {8.0, 2.0, 0.5}) {
    r.pixel_error = tau;
    const TerrainMesh m = t.refine(r);
    expect_valid(t, m, std::nullopt);
    EXPECT_GE(m.triangles.size(), previous);
    previous = m.triangles.size();
    // Mean triangle area near the eye (y < 16) is smaller than far away (y > 48).
    double near_area = 0, far_area = 0;
    std::size_t near_count = 0, far_count = 0;
    for (const Tri& tri : m.triangles) {
      const double cy = (m.samples[tri[0]][1] + m.samples[tri[1]][1] + m.samples[tri[2]][1]) / 3.0;
      const double area = 0.5 * double(cross2(m.samples[tri[0]], m.samples[tri[1]], m.samples[tri[2]]));
      if (cy < 16) near_area += area, ++near_count;
      if (cy > 48) far_area += area, ++far_count;
    }
    ASSERT_GT(near_count, 0u);
    ASSERT_GT(far_count, 0u);
    EXPECT_LT(near_area / double(near_count), far_area / double(far_count));
  }
  // Looking away from the terrain: culled but for what is around the eye.
  v.camera.target = Vec3f(32, -50, 12);
  r.view = v;
  const TerrainMesh away = t.refine(r);
  expect_valid(t, away, std::nullopt);
  EXPECT_LT(away.triangles.size() * 4, previous);
  // Both criteria at once: at least what each gives.
  r.view->camera.target = Vec3f(32, 40, 0);
  r.max_error = 1.0;
  const TerrainMesh both = t.refine(r);
  expect_valid(t, both, 1.0);
  EXPECT_GE(both.triangles.size(), t.refine(by_error(1.0)).triangles.size());
}

TEST(Terrain, TilesMeetWithoutCracks) {
  const HeightField f = noise(33, 30, 5, 3);
  const Terrain t(f);
  for (const std::uint32_t tiles : {2u, 4u}) {
    for (const double e : {0.5, 2.0}) {
      const TerrainMesh m = t.refine_tiles(by_error(e), tiles);
      expect_valid(t, m, e);
    }
  }
  EXPECT_THROW(t.refine_tiles(by_error(1.0), 3), Error);
  EXPECT_THROW(t.refine_tiles(by_error(1.0), 32), Error);
}

TEST(Terrain, MappedFileGivesTheSameMeshes) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "geods_terrain_test.geodsterrain";
  const HeightField f = real_field();
  const Terrain t(f, {.z_scale = 0.5});  // the matrix layout (the default); the file is interleaved
  ASSERT_EQ(t.layout().layout(), Layout::matrix);
  t.save(path);
  for (const auto verify : {Archive::Verify::checksums, Archive::Verify::structure_only}) {
    const Terrain u = Terrain::load(path, verify);
    EXPECT_TRUE(u.records().mapped());
    EXPECT_EQ(u.width(), t.width());
    ASSERT_EQ(u.layout().layout(), Layout::interleaved);
    const std::uint32_t n = std::uint32_t(t.layout().n());
    for (std::uint32_t y = 0; y < n; ++y)
      for (std::uint32_t x = 0; x < n; ++x)
        ASSERT_EQ(std::memcmp(&u.record(x, y), &t.record(x, y), sizeof(VertexRecord)), 0) << x << " " << y;
    for (const double e : {1.0, 10.0}) {
      const TerrainMesh a = t.refine(by_error(e)), b = u.refine(by_error(e));
      EXPECT_EQ(a.strip, b.strip);
      EXPECT_EQ(a.triangles, b.triangles);
      EXPECT_EQ(a.vertices, b.vertices);
    }
  }
  // An interleaved terrain writes the same file.
  const std::filesystem::path path2 = std::filesystem::temp_directory_path() / "geods_terrain_test2.geodsterrain";
  Terrain(f, {.z_scale = 0.5, .layout = Layout::interleaved}).save(path2);
  const auto bytes = [](const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(bytes(path), bytes(path2));
  std::filesystem::remove(path2);
  // Truncated and foreign files.
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size - 100);
  EXPECT_THROW(Terrain::load(path), Error);
  std::filesystem::remove(path);
  EXPECT_THROW(Terrain::load(path), Error);
}

TEST(Terrain, BadInput) {
  EXPECT_THROW(Terrain(field_of(1, 9, [](double, double) { return 0.0; })), Error);
  EXPECT_THROW(Terrain(field_of(9, 1, [](double, double) { return 0.0; })), Error);
  EXPECT_THROW(Terrain(field_of(4, 4, [](double, double) { return std::nan(""); })), Error);
  EXPECT_THROW(Terrain(field_of(4, 4, [](double, double) { return INFINITY; })), Error);
  HeightField f = noise(9, 9, 1);
  f.spacing = {0, 1};
  EXPECT_THROW(Terrain{f}, Error);
  const Terrain t(noise(9, 9, 1));
  EXPECT_THROW(t.refine({}), Error);
  EXPECT_THROW(t.refine(by_error(-1.0)), Error);
  EXPECT_THROW(t.refine(by_error(std::nan(""))), Error);
  Refinement r;
  r.view = TerrainView{};
  r.pixel_error = 0;
  EXPECT_THROW(t.refine(r), Error);
  r.pixel_error = 1;
  r.view->camera.eye = r.view->camera.target;
  EXPECT_THROW(t.refine(r), Error);
}

TEST(Terrain, MissingSamplesAreFilledFromTheNearestValidOne) {
  HeightField f = noise(20, 20, 9);
  for (std::size_t y = 5; y < 9; ++y)
    for (std::size_t x = 0; x < 20; ++x) f.heights[y * 20 + x] = NAN;
  f.heights[0] = NAN;
  HeightField g = f;
  EXPECT_EQ(fill_missing(g), 81u);
  EXPECT_EQ(g.heights[0], f.heights[1]);        // (1, 0) is nearer than (0, 1)? equal: ties to the lowest row
  EXPECT_EQ(g(3, 5), f(3, 4));
  EXPECT_EQ(g(3, 8), f(3, 9));
  const Terrain t(f);
  EXPECT_EQ(t.stats().filled_samples, 81u);
  expect_valid(t, t.refine(by_error(1.0)), 1.0);
}

TEST(Terrain, GreedyTinsWithinTheBoundAndTiled) {
  const std::vector<std::pair<std::string, HeightField>> fields = {
      {"noise", noise(21, 17, 4, 3)},
      {"cliff", field_of(30, 25, [](double x, double y) { return x + 0.3 * y > 14 ? 50.0 : 0.0; })},
      {"constant", field_of(9, 5, [](double, double) { return 4.0; })},
      {"real", real_field()},
  };
  for (const auto& [name, f] : fields) {
    SCOPED_TRACE(name);
    const Terrain t(f);
    for (const double e : {0.0, 1.0, 10.0}) {
      for (const std::uint32_t tiles : {1u, 3u}) {
        SCOPED_TRACE(e);
        SCOPED_TRACE(tiles);
        const TerrainMesh m = t.tin(e, tiles);
        expect_tiling(m, t.width(), t.height());
        EXPECT_TRUE(m.strip.empty());
        const double brute = brute_force_error(m, t);
        EXPECT_LE(brute, e + 1e-6 * (1 + e));
        EXPECT_NEAR(t.measure_error(m), brute, 1e-6 * (1 + brute));
      }
    }
  }
  // Fewer triangles than the 4-8 mesh at the same measured error on real data (2314 vs 3457).
  const Terrain t(real_field());
  const TerrainMesh grid = t.refine(by_error(5.0)), tin = t.tin(t.measure_error(grid));
  EXPECT_LT(tin.triangles.size() * 5, grid.triangles.size() * 4);
  EXPECT_EQ(t.tin(1e9).triangles.size(), 2u);
  EXPECT_THROW(t.tin(-1), Error);
  EXPECT_THROW(t.tin(1, 0), Error);
}

// The TIN's triangle scans (AVX2 rows where the CPU has them) give the same
// mesh at every SIMD level: the same errors, the same worst samples.
TEST(Terrain, GreedyTinTheSameAtEverySimdLevel) {
  const Terrain t(real_field());
  const test::LevelGuard guard;
  set_simd_level(SimdLevel::portable);
  const TerrainMesh portable = t.tin(1.0), portable_tiles = t.tin(3.0, 2);
  set_simd_level(guard.saved);
  const TerrainMesh best = t.tin(1.0), best_tiles = t.tin(3.0, 2);
  EXPECT_EQ(best.samples, portable.samples);
  EXPECT_EQ(best.triangles, portable.triangles);
  EXPECT_EQ(best_tiles.samples, portable_tiles.samples);
  EXPECT_EQ(best_tiles.triangles, portable_tiles.triangles);
  EXPECT_GT(best.triangles.size(), 1000u);
}

// The fine levels' AVX2 kernels, the AVX2 and AVX-512 row kernels and the
// nesting's give the records of the portable code bit for bit: fields wide
// enough for every kernel (spacing 1 to 32, eight lanes up to 128 samples
// apart in the 1025-sample grid), padded on one side or both,
// non-square, the heights scaled from 1e-3 to 1e30, in both layouts.
TEST(Terrain, RecordsTheSameAtEverySimdLevel) {
  const std::vector<std::pair<HeightField, double>> fields = {
      {noise(257, 257, 21), 1}, {noise(300, 170, 22, 1000), 1e-3}, {noise(129, 400, 23), 1e30}, {noise(1025, 600, 24), 1},
      {real_field(), 1}};
  const test::LevelGuard guard;
  for (const auto& [f, scale] : fields)
    for (const Layout layout : {Layout::interleaved, Layout::matrix}) {
      SCOPED_TRACE(std::to_string(f.width) + " x " + std::to_string(f.height));
      set_simd_level(SimdLevel::portable);
      const Terrain portable(f, {.z_scale = scale, .layout = layout});
      for (const SimdLevel l : {std::min(guard.saved, SimdLevel::avx2), guard.saved}) {
        set_simd_level(l);
        const Terrain t(f, {.z_scale = scale, .layout = layout});
        ASSERT_EQ(t.records().size(), portable.records().size());
        EXPECT_EQ(std::memcmp(t.records().data(), portable.records().data(), t.records().size() * sizeof(VertexRecord)), 0);
      }
    }
}

// Every tile of tin(e, tiles) is tin_tile() of its block of samples on its own
// (with the whole field's border limit), shifted: tiles can be computed apart.
TEST(Terrain, TinTilesComputedApartEqualTheTiledTin) {
  const HeightField f = real_field();
  const Terrain t(f);
  const float lo = *std::min_element(f.heights.begin(), f.heights.end());
  const float hi = *std::max_element(f.heights.begin(), f.heights.end());
  for (const std::uint32_t tiles : {1u, 3u}) {
    const double e = 2.0;
    const TerrainMesh whole = t.tin(e, tiles);
    std::multiset<std::array<std::array<std::uint32_t, 2>, 3>> expected, got;
    for (const Tri& tri : whole.triangles) {
      std::array<std::array<std::uint32_t, 2>, 3> c{whole.samples[tri[0]], whole.samples[tri[1]], whole.samples[tri[2]]};
      std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
      expected.insert(c);
    }
    const std::size_t W = f.width, H = f.height;
    for (std::uint32_t ty = 0; ty < tiles; ++ty)
      for (std::uint32_t tx = 0; tx < tiles; ++tx) {
        const std::size_t x0 = tx * (W - 1) / tiles, x1 = (tx + 1) * (W - 1) / tiles;
        const std::size_t y0 = ty * (H - 1) / tiles, y1 = (ty + 1) * (H - 1) / tiles;
        std::vector<float> block;
        for (std::size_t y = y0; y <= y1; ++y)
          for (std::size_t x = x0; x <= x1; ++x) block.push_back(f.heights[y * W + x]);
        const TerrainMesh m = tin_tile(block, x1 - x0 + 1, y1 - y0 + 1, e, tin_border_limit(e, lo, hi));
        for (const Tri& tri : m.triangles) {
          std::array<std::array<std::uint32_t, 2>, 3> c;
          for (int k = 0; k < 3; ++k)
            c[k] = {m.samples[tri[k]][0] + std::uint32_t(x0), m.samples[tri[k]][1] + std::uint32_t(y0)};
          std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
          got.insert(c);
        }
      }
    EXPECT_EQ(got, expected) << tiles;
  }
  const std::vector<float> z(4, 1.0f);
  EXPECT_THROW(tin_tile(z, 2, 2, -1, 0), Error);
  EXPECT_THROW(tin_tile(z, 4, 1, 1, 0), Error);
  EXPECT_THROW(tin_tile(z, 2, 2, 1, 2), Error);
  const std::vector<float> bad{1, 2, std::numeric_limits<float>::quiet_NaN(), 4};
  EXPECT_THROW(tin_tile(bad, 2, 2, 1, 0), Error);
}

}  // namespace
}  // namespace geods::terrain
