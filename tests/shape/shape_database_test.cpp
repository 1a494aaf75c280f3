// The retrieval database against brute force over the feature vectors, the
// retrieval of transformed copies, files (round trip, other versions, corrupt
// bytes) and the PSB measures against a direct computation.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include "common/data_files.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"
#include "geods/shape/retrieval.hpp"
#include "geods/shape/shape_database.hpp"
#include "shape/test_meshes.hpp"

namespace geods::shape {
namespace {

namespace fs = std::filesystem;

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("geods_shape_" + std::to_string(::getpid()) + "_" + name);
}

DescriptorOptions small_options(const char* spec = "d2") {
  DescriptorOptions o = parse_descriptor(spec);
  o.distribution.samples = 1 << 15;
  o.distribution.bins = 32;
  return o;
}

// Brute force: every vector's Euclidean distance, sorted (ties by id).
std::vector<std::pair<double, std::uint64_t>> brute_force(const ShapeDatabase& db, const std::vector<float>& q) {
  std::vector<std::pair<double, std::uint64_t>> all;
  for (std::uint64_t id = 0; id < db.size(); ++id) {
    const std::vector<float> d = db.descriptor(id);
    double s = 0;
    for (std::size_t i = 0; i < q.size(); ++i) s += (double(q[i]) - d[i]) * (double(q[i]) - d[i]);
    all.push_back({std::sqrt(s), id});
  }
  std::sort(all.begin(), all.end());
  return all;
}

// Random histograms (rows summing to 1), clustered like descriptors of similar shapes.
std::vector<float> random_descriptors(std::size_t n, std::size_t dim, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<float> centers(20 * dim), out(n * dim);
  for (float& c : centers) c = u(g);
  for (std::size_t i = 0; i < n; ++i) {
    const float* c = centers.data() + (g() % 20) * dim;
    float sum = 0;
    for (std::size_t j = 0; j < dim; ++j) sum += out[i * dim + j] = c[j] + 0.05f * u(g);
    for (std::size_t j = 0; j < dim; ++j) out[i * dim + j] /= sum;
  }
  // Duplicates: exact ties must come out by id.
  for (std::size_t i = 0; i + 1 < n; i += 37) std::copy_n(out.data() + i * dim, dim, out.data() + (i + 1) * dim);
  return out;
}

std::vector<std::string> numbered(std::size_t n, const std::string& prefix = "s") {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < n; ++i) out.push_back(prefix + std::to_string(i));
  return out;
}

TEST(ShapeDatabase, ExactAndApproximateKnnMatchBruteForceAcrossAdds) {
  ShapeDatabase db(small_options("d2+a3:0.5"));
  const std::size_t dim = db.dimension();
  ASSERT_EQ(dim, 64u);
  // A batch (one block), then single adds through the dynamization (more blocks).
  const std::vector<float> batch = random_descriptors(500, dim, 1);
  db.add_descriptors(numbered(500), batch);
  const std::vector<float> more = random_descriptors(77, dim, 2);
  for (std::size_t i = 0; i < 77; ++i) {
    const std::string name = "late" + std::to_string(i);
    EXPECT_EQ(db.add_descriptors(std::span(&name, 1), std::span(more.data() + i * dim, dim)).front(), 500 + i);
  }
  db.validate();
  EXPECT_GT(db.stats().structures, 1u) << "single adds should go to new blocks, not rebuild one tree";
  const std::vector<float> queries = random_descriptors(60, dim, 3);
  for (std::size_t q = 0; q < 60; ++q) {
    std::vector<float> query(queries.begin() + q * dim, queries.begin() + (q + 1) * dim);
    if (q % 10 == 0) query = db.descriptor(q * 9);  // a stored vector: distance 0 and its duplicate
    const auto truth = brute_force(db, query);
    for (std::size_t k : {1, 5, 17}) {
      const auto exact = db.query_descriptor(query, k);
      ASSERT_EQ(exact.size(), k);
      for (std::size_t i = 0; i < k; ++i) {
        EXPECT_NEAR(exact[i].distance, truth[i].first, 1e-5) << "query " << q << " rank " << i;
        EXPECT_EQ(exact[i].name, db.name(exact[i].id));
      }
      const auto approx = db.query_descriptor(query, k, 0.5);
      for (std::size_t i = 0; i < k; ++i) EXPECT_LE(approx[i].distance, 1.5 * truth[i].first + 1e-5);
    }
  }
  EXPECT_EQ(db.query_descriptor(db.descriptor(0), 10000).size(), db.size());
}

TEST(ShapeDatabase, RetrievesTransformedCopiesAtPrecisionOne) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const TriMesh teapot = test::data_mesh("teapot.obj");
  const std::vector<std::pair<std::string, TriMesh>> originals = {
      {"bunny", bunny}, {"teapot", teapot}, {"sphere", testing::icosphere(3)},
      {"cube", testing::cube()}, {"cylinder", testing::cylinder(48, 1, 4)}};
  std::vector<std::string> names, labels;
  std::vector<TriMesh> meshes;
  const std::size_t copies = 5;
  for (const auto& [label, mesh] : originals) {
    const float size = mesh.bounds().extent().maxCoeff();
    const TriMesh versions[copies] = {
        mesh,
        testing::transformed(mesh, testing::rotation(0.7f, {1, 1, 0}), {3, 4, 5}, 1),
        testing::transformed(mesh, testing::rotation(2.1f, {0, 0, 1}), Vec3f::Zero(), 8),
        testing::subdivide(mesh),
        testing::decimate(testing::subdivide(testing::subdivide(mesh)), size / 30)};
    for (std::size_t c = 0; c < copies; ++c) {
      names.push_back(label + std::to_string(c));
      labels.push_back(label);
      meshes.push_back(versions[c]);
    }
  }
  DescriptorOptions o = small_options("combined");
  ShapeDatabase db(o);
  db.add(names, meshes, labels);
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const auto matches = db.query(meshes[i], copies);
    ASSERT_EQ(matches.size(), copies);
    for (const ShapeMatch& m : matches) EXPECT_EQ(m.label, labels[i]) << names[i] << " found " << m.name;
  }
  const RetrievalScores scores = evaluate_retrieval(db, copies - 1);
  EXPECT_EQ(scores.queries, meshes.size());
  EXPECT_EQ(scores.classes, originals.size());
  EXPECT_DOUBLE_EQ(scores.nn_rate, 1.0);
  EXPECT_DOUBLE_EQ(scores.first_tier, 1.0);
  EXPECT_DOUBLE_EQ(scores.precision_at_k, 1.0);
}

TEST(ShapeDatabase, SaveLoadRoundTripMapsAndKeepsAdding) {
  ShapeDatabase db(small_options("d2+d1:2"));
  const std::size_t dim = db.dimension();
  std::vector<std::string> labels;
  for (std::size_t i = 0; i < 300; ++i) labels.push_back(i % 3 ? "chair" : "");
  db.add_descriptors(numbered(300), random_descriptors(300, dim, 4), labels);
  db.add("bunny", test::data_mesh("bunny.ply"), "animal");
  const fs::path path = temp_file("db.geodsshapes");
  db.save(path);
  ShapeDatabase loaded = ShapeDatabase::load(path);
  EXPECT_EQ(descriptor_name(loaded.options()), descriptor_name(db.options()));
  EXPECT_EQ(loaded.options().distribution.samples, db.options().distribution.samples);
  EXPECT_EQ(loaded.names(), db.names());
  EXPECT_EQ(loaded.labels(), db.labels());
  const std::vector<float> queries = random_descriptors(20, dim, 5);
  for (std::size_t q = 0; q < 20; ++q) {
    const std::span<const float> query(queries.data() + q * dim, dim);
    const auto a = db.query_descriptor(query, 7), b = loaded.query_descriptor(query, 7);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].id, b[i].id);
      EXPECT_EQ(a[i].distance, b[i].distance);
    }
  }
  // Adding to a loaded database continues the ids and answers like adding to the original.
  const TriMesh teapot = test::data_mesh("teapot.obj");
  EXPECT_EQ(loaded.add("teapot", teapot, "kitchen"), 301u);
  EXPECT_EQ(loaded.query(teapot, 1).front().name, "teapot");
  EXPECT_EQ(loaded.query(teapot, 1).front().distance, 0.0);
  fs::remove(path);
}

TEST(ShapeDatabase, RefusesOtherVersionsKindsAndCorruptFiles) {
  const fs::path path = temp_file("other.geodsshapes");
  {
    ArchiveWriter w(std::string(kShapeDatabaseArchiveKind), kShapeDatabaseArchiveVersion + 1);
    w.add_value("shapes", std::uint64_t(0));
    w.write(path);
  }
  try {
    ShapeDatabase::load(path);
    FAIL() << "a database of another version loaded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path.filename().string()), std::string::npos) << e.what();
  }
  ShapeDatabase db(small_options());
  db.add_descriptors(numbered(50), random_descriptors(50, db.dimension(), 6));
  db.tree().save(path);  // a dynamic.KdTree, not a database
  EXPECT_THROW(ShapeDatabase::load(path), Error);
  db.save(path);
  const auto bytes = fs::file_size(path);
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(bytes - 100));
    f.put('\x7f');
  }
  EXPECT_THROW(ShapeDatabase::load(path), Error);
  fs::resize_file(path, bytes / 2);
  EXPECT_THROW(ShapeDatabase::load(path), Error);
  EXPECT_THROW(ShapeDatabase::load(temp_file("missing")), Error);
  fs::remove(path);
}

TEST(ShapeDatabase, BadInputAddsNothing) {
  ShapeDatabase db(small_options());
  TriMesh bad = testing::cube();
  bad.vertices[2].x() = std::nanf("");
  const std::vector<std::string> names{"good", "bad"};
  const std::vector<TriMesh> meshes{testing::cube(), bad};
  try {
    db.add(names, meshes);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'bad'"), std::string::npos) << e.what();
  }
  EXPECT_EQ(db.size(), 0u);
  EXPECT_THROW(db.add("empty", TriMesh{}), Error);
  EXPECT_THROW(db.add_descriptors(numbered(2), std::vector<float>(5)), Error);
  std::vector<float> nan_row(db.dimension(), 0.f);
  nan_row[3] = NAN;
  EXPECT_THROW(db.add_descriptors(numbered(1), nan_row), Error);
  EXPECT_THROW(db.add_descriptors(numbered(1), std::vector<float>(db.dimension()), numbered(2)), Error);
  EXPECT_EQ(db.size(), 0u);
  db.validate();
  EXPECT_TRUE(db.query(testing::cube(), 3).empty());
  EXPECT_THROW(db.query_descriptor(std::vector<float>(3), 1), Error);
  EXPECT_THROW(db.query(testing::cube(), 1, -1), Error);
  DescriptorOptions o;
  o.weights.clear();
  EXPECT_THROW(ShapeDatabase{o}, Error);
}

// ---------------------------------------------------------------- the measures
TEST(Retrieval, ScoreRankingByHand) {
  RetrievalScores s;
  s.k = 3;
  s.recall = {0.5, 1.0};
  s.precision = {0, 0};
  // Class of 3 (two others); ranking: miss, hit, miss, hit.
  score_ranking({false, true, false, true}, 3, s);
  EXPECT_EQ(s.nn_rate, 0.0);
  EXPECT_DOUBLE_EQ(s.precision_at_k, 1.0 / 3);
  EXPECT_DOUBLE_EQ(s.first_tier, 0.5);   // one of the two among the 2 nearest
  EXPECT_DOUBLE_EQ(s.second_tier, 1.0);  // both among the 4 nearest
  EXPECT_DOUBLE_EQ(s.mean_average_precision, (0.5 + 0.5) / 2);
  EXPECT_DOUBLE_EQ(s.precision[0], 0.5);
  EXPECT_DOUBLE_EQ(s.precision[1], 0.5);
}

TEST(Retrieval, MatchesDirectComputationOnRandomLabels) {
  ShapeDatabase db(small_options());
  const std::size_t n = 120, dim = db.dimension();
  std::vector<std::string> labels;
  std::mt19937 g(8);
  const std::vector<std::string> classes{"c0", "c1", "c2", "c3", "c4", "c5"};
  for (std::size_t i = 0; i < n; ++i) labels.push_back(i % 11 == 0 ? "" : i % 17 == 0 ? "single" : classes[g() % 6]);
  labels[17] = "single";  // exactly one member: never a query
  for (std::size_t i = 34; i < n; i += 17) labels[i] = "c0";
  const std::vector<float> rows = random_descriptors(n, dim, 9);
  db.add_descriptors(numbered(n), rows, labels);
  const std::size_t k = 4;
  const RetrievalScores s = evaluate_retrieval(db, k, 10);
  // Direct: sort all others by brute-force distance.
  std::map<std::string, std::size_t> size;
  for (const auto& l : labels) size[l]++;
  double nn = 0, pk = 0, ft = 0, st = 0;
  std::size_t queries = 0;
  for (std::size_t q = 0; q < n; ++q) {
    if (labels[q].empty() || size[labels[q]] < 2) continue;
    ++queries;
    auto ranked = brute_force(db, db.descriptor(q));
    ranked.erase(std::find_if(ranked.begin(), ranked.end(), [&](const auto& p) { return p.second == q; }));
    const std::size_t r = size[labels[q]] - 1;
    auto count = [&](std::size_t first) {
      std::size_t c = 0;
      for (std::size_t i = 0; i < std::min(first, ranked.size()); ++i) c += labels[ranked[i].second] == labels[q];
      return double(c);
    };
    nn += count(1);
    pk += count(k) / double(k);
    ft += count(r) / double(r);
    st += count(2 * r) / double(r);
  }
  EXPECT_EQ(s.queries, queries);
  EXPECT_EQ(s.shapes, n);
  EXPECT_NEAR(s.nn_rate, nn / double(queries), 1e-12);
  EXPECT_NEAR(s.precision_at_k, pk / double(queries), 1e-12);
  EXPECT_NEAR(s.first_tier, ft / double(queries), 1e-12);
  EXPECT_NEAR(s.second_tier, st / double(queries), 1e-12);
  ASSERT_EQ(s.precision.size(), 10u);
  for (std::size_t l = 1; l < 10; ++l) EXPECT_LE(s.precision[l], s.precision[l - 1] + 1e-12) << "interpolated precision rises";
  EXPECT_THROW(evaluate_retrieval(db, 0), Error);
}

}  // namespace
}  // namespace geods::shape
