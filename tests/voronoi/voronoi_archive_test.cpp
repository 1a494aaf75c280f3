// Delaunay2 and Voronoi2 save/load: a loaded structure equals the saved one
// (arrays, queries, and for Delaunay2 further insert/remove step by step against
// the unsaved original), validate() passes; truncated, corrupt, wrong-kind and
// missing files raise geods::Error.
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <unistd.h>
#include <string>
#include <utility>
#include <vector>

#include "common/archive_files.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/voronoi2.hpp"

namespace geods::voronoi {
namespace {

namespace fs = std::filesystem;

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("geods_voronoi_archive_" + std::to_string(::getpid()) + "_" + name);
}

std::vector<Vec2d> random_points(std::size_t n, std::uint64_t seed, bool integer = false) {
  Rng rng(seed);
  std::vector<Vec2d> p(n);
  for (auto& q : p) q = integer ? Vec2d(double(rng.below(8)), double(rng.below(8))) : Vec2d(rng.uniform(), rng.uniform());
  return p;
}

void expect_same(const Delaunay2& a, const Delaunay2& b) {
  ASSERT_EQ(a.points().size(), b.points().size());
  for (std::size_t i = 0; i < a.points().size(); ++i) {
    EXPECT_EQ(a.points()[i], b.points()[i]);
    EXPECT_EQ(a.representative(std::uint32_t(i)), b.representative(std::uint32_t(i)));
  }
  EXPECT_EQ(a.triangles(), b.triangles());
  EXPECT_EQ(a.halfedges(), b.halfedges());
  EXPECT_EQ(a.hull(), b.hull());
  EXPECT_EQ(a.constrained(), b.constrained());
  EXPECT_EQ(a.segments(), b.segments());
  EXPECT_EQ(a.intersection_points(), b.intersection_points());
  EXPECT_EQ(a.inside(), b.inside());
  const Delaunay2Stats sa = a.stats(), sb = b.stats();
  EXPECT_EQ(sa.vertices, sb.vertices);
  EXPECT_EQ(sa.flips, sb.flips);
  EXPECT_EQ(sa.walk_steps, sb.walk_steps);
  EXPECT_EQ(sa.dag_nodes, sb.dag_nodes);
  Rng rng(7);
  for (int k = 0; k < 200; ++k) {
    const Vec2d q(rng.uniform() * 1.4 - 0.2, rng.uniform() * 1.4 - 0.2);
    EXPECT_EQ(a.locate(q), b.locate(q));
    EXPECT_EQ(a.nearest(q), b.nearest(q));
  }
  for (std::uint32_t v = 0; v < a.points().size(); ++v) EXPECT_EQ(a.neighbors(v), b.neighbors(v));
}

Delaunay2 round_trip(const Delaunay2& dt, const std::string& name) {
  const fs::path path = temp_file(name);
  dt.save(path);
  Delaunay2 loaded = Delaunay2::load(path);
  fs::remove(path);
  loaded.validate();
  return loaded;
}

TEST(Delaunay2Archive, RoundTripThenUpdatesMatchTheOriginal) {
  Delaunay2 original(random_points(2000, 1));
  Delaunay2 loaded = round_trip(original, "uniform");
  expect_same(original, loaded);
  Rng rng(3);
  for (int k = 0; k < 50; ++k) {
    const Vec2d p(rng.uniform() * 1.2 - 0.1, rng.uniform() * 1.2 - 0.1);
    EXPECT_EQ(original.insert(p), loaded.insert(p));
    const std::uint32_t v = std::uint32_t(rng.below(original.points().size()));
    if (original.representative(v) != Delaunay2::no_edge) {
      original.remove(v);
      loaded.remove(v);
    }
  }
  loaded.validate();
  expect_same(original, loaded);
  // Saved after updates (freed triangle slots in use), loaded again.
  expect_same(original, round_trip(loaded, "updated"));
}

TEST(Delaunay2Archive, DuplicatesDegenerateAndHistoryDag) {
  expect_same(Delaunay2(random_points(300, 2, true)), round_trip(Delaunay2(random_points(300, 2, true)), "grid"));
  const std::vector<Vec2d> line = {{0, 0}, {2, 2}, {1, 1}, {1, 1}, {3, 3}};
  Delaunay2 collinear(line);
  Delaunay2 loaded = round_trip(collinear, "collinear");
  ASSERT_TRUE(loaded.degenerate());
  expect_same(collinear, loaded);
  collinear.insert({0, 3});
  loaded.insert({0, 3});
  expect_same(collinear, loaded);
  expect_same(Delaunay2(), round_trip(Delaunay2(), "empty"));
  Delaunay2::Options dag;
  dag.location = Delaunay2Location::history_dag;
  expect_same(Delaunay2(random_points(500, 4), dag), round_trip(Delaunay2(random_points(500, 4), dag), "dag"));
}

TEST(Delaunay2Archive, ConstrainedRoundTrip) {
  std::vector<Vec2d> p = random_points(200, 5);
  for (Vec2d q : {Vec2d(0, 0), Vec2d(1, 0), Vec2d(1, 1), Vec2d(0, 1), Vec2d(0.5, -0.2), Vec2d(0.5, 1.2)}) p.push_back(q);
  const std::uint32_t n = std::uint32_t(p.size());
  const std::vector<Delaunay2::Segment> segments = {{n - 6, n - 5}, {n - 5, n - 4}, {n - 4, n - 3}, {n - 3, n - 6},
                                                    {n - 2, n - 1}};  // the last crosses the square
  Delaunay2 original(p, segments);
  ASSERT_FALSE(original.intersection_points().empty());
  Delaunay2 loaded = round_trip(original, "constrained");
  expect_same(original, loaded);
  EXPECT_EQ(original.insert({0.3, 0.3}), loaded.insert({0.3, 0.3}));
  expect_same(original, loaded);
}

TEST(Delaunay2Archive, LoadedArraysAreViewsUntilTheFirstChange) {
  const Delaunay2 original(random_points(1000, 11));
  const fs::path path = temp_file("mapped");
  original.save(path);
  Delaunay2 loaded = Delaunay2::load(path);
  fs::remove(path);  // the mapping outlives the name
  EXPECT_TRUE(loaded.triangles().mapped());
  EXPECT_TRUE(loaded.halfedges().mapped());
  EXPECT_TRUE(loaded.hull().mapped());
  EXPECT_FALSE(original.triangles().mapped());
  expect_same(original, loaded);
  const Voronoi2 from_loaded(loaded), from_original(original);  // the dual, built from the views
  EXPECT_EQ(from_loaded.vertices(), from_original.vertices());
  const Delaunay2 copy = loaded;  // copies share the views
  EXPECT_TRUE(copy.triangles().mapped());
  Delaunay2 changed = original;
  const Vec2d p(0.25, 0.75);
  EXPECT_EQ(changed.insert(p), loaded.insert(p));  // copies the views into arrays of its own
  EXPECT_FALSE(loaded.triangles().mapped());
  EXPECT_FALSE(loaded.halfedges().mapped());
  EXPECT_TRUE(copy.triangles().mapped());  // the copy still reads the file
  loaded.validate();
  expect_same(changed, loaded);
  expect_same(original, copy);
}

TEST(Delaunay2Archive, SmallAndDegenerateSetsRoundTrip) {
  const std::vector<std::vector<Vec2d>> sets = {
      {{0.5, 0.5}},                                          // one point
      {{0, 0}, {1, 1}},                                      // two
      {{2, 2}, {2, 2}, {2, 2}},                              // one point three times
      {{0, 0}, {1, 0}, {0, 1}},                              // one triangle
      {{0, 0}, {1, 0}, {0, 1}, {1, 0}, {0, 0}},              // one triangle with duplicates
      {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0.5}, {1, 1}},  // co-circular square, its centre, a duplicate
  };
  for (std::size_t k = 0; k < sets.size(); ++k) {
    SCOPED_TRACE("set " + std::to_string(k));
    Delaunay2 original(sets[k]);
    Delaunay2 loaded = round_trip(original, "small" + std::to_string(k));
    EXPECT_EQ(loaded.degenerate(), original.degenerate());
    expect_same(original, loaded);
    for (const Vec2d& p : {Vec2d(0.3, 0.2), Vec2d(2, 2), Vec2d(-1, 0.5)}) EXPECT_EQ(original.insert(p), loaded.insert(p));
    expect_same(original, loaded);
    original.remove(0);
    loaded.remove(0);
    loaded.validate();
    expect_same(original, loaded);
  }
  // Co-circular grid points with many duplicates, then removals after loading.
  Delaunay2 grid(random_points(400, 12, true));
  Delaunay2 loaded = round_trip(grid, "grid_remove");
  for (std::uint32_t v = 0; v < 400; v += 3)
    if (grid.representative(v) != Delaunay2::no_edge) {
      grid.remove(v);
      loaded.remove(v);
    }
  loaded.validate();
  expect_same(grid, loaded);
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

// A Delaunay2 archive of points `xy` (each its own vertex, in order), the
// closed triangulation (vert, twin) and its public view (finite triangles in
// order, `hull` as given), written with matching checksums.
void write_triangulation(const fs::path& path, const std::vector<double>& xy, const std::vector<std::uint32_t>& vert,
                         const std::vector<std::uint32_t>& twin, const std::vector<std::uint32_t>& hull = {}) {
  constexpr std::uint32_t none = Delaunay2::no_edge;
  ArchiveWriter w("voronoi.Delaunay2", 2);
  const std::vector<std::uint32_t> no_indices;
  std::vector<std::uint32_t> iota(xy.size() / 2);
  for (std::uint32_t i = 0; i < iota.size(); ++i) iota[i] = i;
  const std::vector<std::uint64_t> counters = {0, 0, 0};
  const std::vector<std::uint8_t> no_marks;
  std::vector<std::uint32_t> public_triangle(vert.size() / 3, none), internal_triangle, triangles, halfedges;
  std::vector<std::uint32_t> vertex_edge(iota.size(), none);
  for (std::uint32_t t = 0; t < vert.size() / 3; ++t)
    if (vert[3 * t] < iota.size() && vert[3 * t + 1] < iota.size() && vert[3 * t + 2] < iota.size()) {
      public_triangle[t] = std::uint32_t(internal_triangle.size());
      internal_triangle.push_back(t);
    }
  for (std::uint32_t t : internal_triangle)
    for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e) {
      triangles.push_back(vert[e]);
      const std::uint32_t f = twin[e] < vert.size() ? twin[e] : 0, other = public_triangle[f / 3];
      halfedges.push_back(other == none ? none : 3 * other + f % 3);
    }
  for (std::uint32_t h = 0; h < vert.size(); ++h)
    if (vert[h] < iota.size()) vertex_edge[vert[h]] = h;
  w.add_value("seed", std::uint64_t(1));
  w.add_value("location", std::uint32_t(0));
  w.add_value("has_constraints", std::uint8_t(0));
  w.add_value("last_triangle", std::uint32_t(0));
  w.add("counters", counters);
  w.add("points", xy);
  w.add("segments", no_indices);
  w.add("intersections", no_indices);
  w.add("representative", iota);
  w.add("coords", xy);
  w.add("original_of", iota);
  w.add("internal_of", iota);
  w.add("vert", vert);
  w.add("twin", twin);
  w.add("free_triangles", no_indices);
  w.add("vertex_edge", vertex_edge);
  w.add("fixed", no_marks);
  w.add("triangles", triangles);
  w.add("halfedges", halfedges);
  w.add("hull", hull);
  w.add("constrained", no_marks);
  w.add("public_triangle", public_triangle);
  w.add("internal_triangle", internal_triangle);
  w.write(path);
}

// The half-edge arrays of counter-clockwise `triangles` closed by a ghost
// triangle (b, a, ghost) beyond each hull edge a -> b; `hull` counter-clockwise.
std::pair<std::vector<std::uint32_t>, std::vector<std::uint32_t>> closed_triangulation(
    const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::vector<std::uint32_t>& hull) {
  std::vector<std::array<std::uint32_t, 3>> all = triangles;
  for (std::size_t k = 0; k < hull.size(); ++k) all.push_back({hull[(k + 1) % hull.size()], hull[k], DelaunayCore::ghost});
  std::vector<std::uint32_t> vert, twin(3 * all.size(), Delaunay2::no_edge);
  for (const auto& t : all) vert.insert(vert.end(), t.begin(), t.end());
  for (std::uint32_t e = 0; e < vert.size(); ++e)
    for (std::uint32_t f = 0; f < vert.size(); ++f)
      if (vert[e] == vert[DelaunayCore::next(f)] && vert[DelaunayCore::next(e)] == vert[f]) twin[e] = f;
  return {vert, twin};
}

// Every truncation raises geods::Error; so does a flipped byte, unless it was
// padding (then the file loads to the same structure: saved again, the same bytes).
template <class Load>
void expect_bad_files_rejected(const fs::path& good, Load load) {
  const std::string bytes = read_bytes(good);
  const fs::path bad = temp_file("bad");
  for (std::size_t size = 0; size < bytes.size(); size += 1 + size / 16) {
    write_bytes(bad, bytes.substr(0, size));
    EXPECT_THROW(load(bad), Error) << "truncated to " << size;
  }
  const fs::path again = temp_file("again");
  int caught = 0;
  for (std::size_t at = 0; at < bytes.size(); at += 1 + at / 32) {
    std::string flipped = bytes;
    flipped[at] ^= 0x10;
    write_bytes(bad, flipped);
    try {
      load(bad).save(again);
      EXPECT_EQ(read_bytes(again), bytes) << "byte " << at << " flipped, and the file loads to something else";
    } catch (const Error&) {
      ++caught;
    }
  }
  EXPECT_GT(caught, 100);
  fs::remove(bad);
  fs::remove(again);
  EXPECT_THROW(load(temp_file("missing")), Error);
}

// Writes the Delaunay2 archive at `from` again to `to` with entry `at` of the
// index section `name` changed to `value` (the checksums made to fit).
void rewrite_index(const fs::path& from, const fs::path& to, const std::string& name, std::size_t at, std::uint32_t value) {
  const Archive a = Archive::open(from, "voronoi.Delaunay2", 2);
  ArchiveWriter w("voronoi.Delaunay2", 2);
  std::vector<std::vector<std::uint32_t>> indices;
  indices.reserve(32);
  for (const char* section : {"seed", "counters"}) w.add(section, a.array<std::uint64_t>(section));
  for (const char* section : {"has_constraints", "fixed", "constrained"}) w.add(section, a.array<std::uint8_t>(section));
  for (const char* section : {"points", "coords"}) w.add(section, a.array<double>(section));
  for (const char* section : {"location", "last_triangle", "segments", "intersections", "representative", "original_of",
                              "internal_of", "vert", "twin", "free_triangles", "vertex_edge", "triangles", "halfedges",
                              "hull", "public_triangle", "internal_triangle"}) {
    std::vector<std::uint32_t>& v = indices.emplace_back(a.array<std::uint32_t>(section).to_vector());
    if (section == name) v.at(at) = value;
    w.add(section, v);
  }
  w.write(to);
}

TEST(Delaunay2Archive, PublicArraysThatDisagreeRaise) {
  std::vector<Vec2d> p = random_points(100, 13);
  for (Vec2d q : {Vec2d(0.1, 0.1), Vec2d(0.9, 0.2), Vec2d(0.5, 0.9)}) p.push_back(q);
  const std::vector<Delaunay2::Segment> segments = {{100, 101}, {101, 102}};
  const Delaunay2 dt(p, segments);
  const fs::path good = temp_file("public_good"), bad = temp_file("public_bad");
  dt.save(good);
  const std::uint32_t t0 = dt.triangles()[0], h0 = dt.halfedges()[0], e0 = 3 * std::uint32_t(dt.triangle_count()) - 1;
  rewrite_index(good, bad, "triangles", 0, t0);  // unchanged: the rewrite itself loads
  expect_same(dt, Delaunay2::load(bad));
  const struct {
    const char* section;
    std::size_t at;
    std::uint32_t value;
  } tampered[] = {
      {"triangles", 0, t0 == 0 ? 1u : 0u},
      {"triangles", 1, t0},
      {"halfedges", 0, h0 == Delaunay2::no_edge ? 0 : Delaunay2::no_edge},
      {"halfedges", e0, e0},
      {"hull", 0, dt.hull()[1]},
      {"public_triangle", 0, Delaunay2::no_edge},
      {"internal_triangle", 0, 1},
      {"vertex_edge", 0, Delaunay2::no_edge},
      {"vertex_edge", 1, 0},
  };
  for (const auto& [section, at, value] : tampered) {
    rewrite_index(good, bad, section, at, value);
    EXPECT_THROW(Delaunay2::load(bad), Error) << section << "[" << at << "] = " << value;
  }
  fs::remove(good);
  fs::remove(bad);
}

TEST(Delaunay2Archive, FreedTrianglesInUseRaise) {
  Delaunay2 dt(random_points(200, 14));
  for (std::uint32_t v = 0; v < 40; v += 2) dt.remove(v);
  const fs::path good = temp_file("freed_good"), bad = temp_file("freed_bad");
  dt.save(good);
  const std::uint32_t freed = Archive::open(good, "voronoi.Delaunay2", 2).array<std::uint32_t>("free_triangles").front();
  expect_same(dt, Delaunay2::load(good));
  const std::uint32_t v = dt.triangles()[0];
  rewrite_index(good, bad, "vert", 3 * freed + 1, v);  // a freed slot that names a vertex
  EXPECT_THROW(Delaunay2::load(bad), Error);
  rewrite_index(good, bad, "vertex_edge", 3, 3 * freed);  // a vertex whose half-edge is in a freed slot
  EXPECT_THROW(Delaunay2::load(bad), Error);
  fs::remove(good);
  fs::remove(bad);
}

TEST(Delaunay2Archive, VersionOneFilesAreRefused) {
  const fs::path path = temp_file("version1");
  ArchiveWriter w("voronoi.Delaunay2", 1);
  w.add_value("seed", std::uint64_t(1));
  w.write(path);
  geods::test::expect_load_error(path, [](const auto& p) { Delaunay2::load(p); }, {"version 1"});
  fs::remove(path);
}

TEST(Delaunay2Archive, BadFilesRaise) {
  const fs::path path = temp_file("good");
  Delaunay2(random_points(100, 6)).save(path);
  expect_bad_files_rejected(path, [](const fs::path& p) { return Delaunay2::load(p); });
  EXPECT_THROW(Voronoi2::load(path), Error);  // another kind
  fs::remove(path);
  // A file with the right kind whose triangulation is wrong (checksums made to fit).
  Delaunay2 dt(random_points(50, 8));
  const std::vector<double> xy = {0, 0, 1, 0, 0, 1};
  const std::vector<std::uint32_t> vert = {0, 2, 1, 1, 2, DelaunayCore::ghost, 2, 0, DelaunayCore::ghost,
                                           0, 1, DelaunayCore::ghost};  // clockwise
  const std::vector<std::uint32_t> twin = {3, 9, 6, 0, 11, 7, 2, 5, 10, 1, 8, 4};
  write_triangulation(path, xy, vert, twin);
  EXPECT_THROW(Delaunay2::load(path), Error);
  fs::remove(path);
}

TEST(Delaunay2Archive, BrokenStructureRaisesAndVerifyFullChecksCircles) {
  // A kite (0, 0), (2, -1), (4, 0), (2, 1) split along its long diagonal 0-2:
  // a closed, counter-clockwise triangulation that is not Delaunay (3 lies in
  // the circle of 0, 1, 2). Its checksums fit, so only the checks see it.
  const std::vector<double> xy = {0, 0, 2, -1, 4, 0, 2, 1};
  const auto [vert, twin] = closed_triangulation({{0, 1, 2}, {0, 2, 3}}, {0, 1, 2, 3});
  const fs::path path = temp_file("kite");
  write_triangulation(path, xy, vert, twin, {0, 1, 2, 3});
  const Delaunay2 loaded = Delaunay2::load(path);  // the cheap checks pass
  EXPECT_EQ(loaded.triangle_count(), 2u);
  EXPECT_EQ(loaded.locate({2, 0.5}), loaded.locate({3, 0.1}));  // queries answer from what was loaded
  EXPECT_THROW(loaded.validate(), Error);
  EXPECT_THROW(Delaunay2::load(path, Archive::Verify::full), Error);
  // Twins that are not mutual, the checksums right.
  std::vector<std::uint32_t> bad_twin = twin;
  std::swap(bad_twin[0], bad_twin[1]);
  write_triangulation(path, xy, vert, bad_twin, {0, 1, 2, 3});
  EXPECT_THROW(Delaunay2::load(path), Error);
  EXPECT_THROW(Delaunay2::load(path, Archive::Verify::structure_only), Error);
  // A public view that is not the one of the triangulation: a hull that starts
  // elsewhere, runs the other way or misses a vertex.
  for (const std::vector<std::uint32_t>& bad_hull :
       {std::vector<std::uint32_t>{1, 2, 3, 0}, std::vector<std::uint32_t>{0, 3, 2, 1}, std::vector<std::uint32_t>{0, 1, 2}}) {
    write_triangulation(path, xy, vert, twin, bad_hull);
    EXPECT_THROW(Delaunay2::load(path), Error);
  }
  // A vertex index out of range.
  std::vector<std::uint32_t> bad_vert = vert;
  bad_vert[1] = 7;
  write_triangulation(path, xy, bad_vert, twin, {0, 1, 2, 3});
  EXPECT_THROW(Delaunay2::load(path), Error);
  fs::remove(path);
}

TEST(Voronoi2Archive, RoundTripAndBadFiles) {
  const std::vector<Vec2d> p = random_points(500, 9);
  const Voronoi2 original(p);
  const fs::path path = temp_file("voronoi");
  original.save(path);
  const Voronoi2 loaded = Voronoi2::load(path);
  loaded.validate();
  ASSERT_EQ(loaded.size(), original.size());
  EXPECT_EQ(loaded.vertices(), original.vertices());
  ASSERT_EQ(loaded.edges().size(), original.edges().size());
  for (std::size_t e = 0; e < original.edges().size(); ++e) {
    const auto &a = original.edges()[e], &b = loaded.edges()[e];
    EXPECT_TRUE(a.site == b.site && a.twin == b.twin && a.next == b.next && a.origin == b.origin && a.target == b.target);
  }
  const AABB2d box = original.default_box();
  for (std::uint32_t i = 0; i < p.size(); i += 7) {
    EXPECT_EQ(loaded.cell_polygon(i, box), original.cell_polygon(i, box));
    const auto na = original.neighbors(i), nb = loaded.neighbors(i);
    EXPECT_EQ(std::vector<std::uint32_t>(na.begin(), na.end()), std::vector<std::uint32_t>(nb.begin(), nb.end()));
  }
  expect_bad_files_rejected(path, [](const fs::path& f) { return Voronoi2::load(f); });
  EXPECT_THROW(Delaunay2::load(path), Error);  // another kind
  fs::remove(path);
  // Links broken or geometry wrong, the checksums right: the links are checked
  // on every load, the geometry with Verify::full.
  const auto write_diagram = [&](std::vector<Voronoi2::Edge> edges, std::vector<Vec2d> vertices) {
    ArchiveWriter w("voronoi.Voronoi2", 1);
    std::vector<std::uint32_t> representative(p.size()), cell_edge(p.size()), offsets{0}, neighbors;
    for (std::uint32_t i = 0; i < p.size(); ++i) {
      representative[i] = original.representative(i);
      cell_edge[i] = original.cell_edge(i);
      const auto nb = original.neighbors(i);
      neighbors.insert(neighbors.end(), nb.begin(), nb.end());
      offsets.push_back(std::uint32_t(neighbors.size()));
    }
    std::vector<double> sites_xy, vertices_xy;
    for (const Vec2d& q : p) sites_xy.insert(sites_xy.end(), {q[0], q[1]});
    for (const Vec2d& q : vertices) vertices_xy.insert(vertices_xy.end(), {q[0], q[1]});
    w.add("points", sites_xy);
    w.add("representative", representative);
    w.add("vertices", vertices_xy);
    w.add("edges", edges);
    w.add("cell_edge", cell_edge);
    w.add("neighbor_offsets", offsets);
    w.add("neighbors", neighbors);
    w.write(path);
  };
  const std::vector<Voronoi2::Edge> edges(original.edges().begin(), original.edges().end());
  const std::vector<Vec2d> vertices(original.vertices().begin(), original.vertices().end());
  write_diagram(edges, vertices);
  EXPECT_NO_THROW(Voronoi2::load(path, Archive::Verify::full));
  std::vector<Voronoi2::Edge> bad = edges;
  bad[bad[0].next].next = bad[0].next;  // a cycle that never comes back to 0: next is no permutation
  write_diagram(bad, vertices);
  EXPECT_THROW(Voronoi2::load(path), Error);
  bad = edges;
  bad[3].twin = 3;
  write_diagram(bad, vertices);
  EXPECT_THROW(Voronoi2::load(path), Error);
  std::vector<Vec2d> moved = vertices;
  moved[0] += Vec2d(0.25, 0.25);
  write_diagram(edges, moved);
  EXPECT_EQ(Voronoi2::load(path).vertices()[0], moved[0]);
  EXPECT_THROW(Voronoi2::load(path, Archive::Verify::full), Error);
  fs::remove(path);
  // Collinear sites (no vertices) round trip too.
  const Voronoi2 line(std::vector<Vec2d>{{0, 0}, {1, 1}, {2, 2}});
  line.save(path);
  EXPECT_EQ(Voronoi2::load(path).edges().size(), line.edges().size());
  fs::remove(path);
}

}  // namespace
}  // namespace geods::voronoi
