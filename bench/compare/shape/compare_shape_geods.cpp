// geods::shape on the shape workload: descriptor time (D2, 2^16 samples, 64 bins) against mesh
// size; retrieval quality and time on the labelled BlendSwap-CC-0 library (D2, and combined
// D2 + A3 + D3); k-NN query time per shape at 100 .. 100,000 descriptors, exact and approximate.
#include <cmath>
#include <random>

#include "geods/shape/shape_database.hpp"
#include "shape_inputs.hpp"

namespace {

using namespace geods;

void describe_variant(const compare::Args& args, const std::string& variant, const TriMesh& mesh) {
  const shape::DescriptorOptions options;  // d2, 65536 samples, 64 bins
  std::vector<float> d;
  const double s = compare::median_time_s(args.reps, [&] { d = shape::describe(mesh, options); });
  double sum = 0;
  for (float v : d) sum += v;
  compare::Record("shape", "geods", variant, args.threads)
      .timing(0, s, 1, args.reps)
      .set("triangles", static_cast<unsigned long long>(mesh.triangles.size()))
      .print(std::abs(sum - 1) < 1e-4);
}

void retrieval_variant(const compare::Args& args, const char* variant, const char* descriptor) {
  const shape_bench::Labelled c = shape_bench::read_collection(args);
  shape::DescriptorOptions options = shape::parse_descriptor(descriptor);
  std::optional<shape::ShapeDatabase> db;
  const double build_s = compare::time_s([&] {
    db.emplace(options);
    db->add(c.names, c.meshes, c.labels);  // descriptors in parallel, one batch into the tree
  });
  shape::RetrievalScores s;
  const double query_s = compare::time_s([&] { s = shape::evaluate_retrieval(*db, 5); });
  // Cross-check: the k-d tree ranking scores as a brute-force L2 ranking.
  const auto brute = shape_bench::score(c.labels, 5, [&](std::size_t i, std::size_t j) {
    const auto a = db->descriptor(i), b = db->descriptor(j);
    return shape::histogram_distance(a, b, shape::Metric::l2);
  });
  compare::Record r("shape", "geods", variant, args.threads);
  r.timing(build_s, query_s, c.meshes.size(), 1).set("descriptor", descriptor).set("dimension",
                                                                                     static_cast<unsigned long long>(db->dimension()));
  shape_bench::put_scores(r, s).print(std::abs(brute.first_tier - s.first_tier) < 1e-9 && s.queries == brute.queries);
}

// Descriptors like real ones: D2 of boxes, cylinders and tori of random proportions,
// jittered (sigma 0.002 per bin) and renormalized.
std::vector<float> jittered(const std::vector<std::vector<float>>& base, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::normal_distribution<float> noise(0, 0.002f);
  const std::size_t dim = base[0].size();
  std::vector<float> out(n * dim);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& b = base[g() % base.size()];
    float sum = 0;
    for (std::size_t j = 0; j < dim; ++j) sum += out[i * dim + j] = std::max(0.0f, b[j] + noise(g));
    for (std::size_t j = 0; j < dim; ++j) out[i * dim + j] /= sum;
  }
  return out;
}

void query_variants(const compare::Args& args) {
  std::mt19937_64 g(7);
  std::uniform_real_distribution<float> u(0.2f, 3.0f);
  shape::DescriptorOptions options;
  options.distribution.samples = 1 << 14;
  std::vector<std::vector<float>> base;
  for (int i = 0; i < 150; ++i) {
    const TriMesh m = i % 3 == 0   ? shape::box_mesh(1, u(g), u(g))
                      : i % 3 == 1 ? shape::cylinder_mesh(48, 1, u(g))
                                   : shape::torus_mesh(1, 0.3f * u(g) / 3, 48, 24);
    base.push_back(shape::describe(m, options));
  }
  const std::size_t dim = base[0].size(), queries = 1000;
  const std::vector<float> q = jittered(base, queries, 99);
  for (std::size_t n : {100, 1000, 10000, 100000}) {
    n = args.scaled(n);
    const std::vector<float> rows = jittered(base, n, n);
    std::vector<std::string> names(n);
    for (std::size_t i = 0; i < n; ++i) names[i] = std::to_string(i);
    std::optional<shape::ShapeDatabase> db;
    const double build_s = compare::median_time_s(args.reps, [&] {
      db.emplace(options);
      db->add_descriptors(names, rows);
    });
    const std::string size = n >= 1000 ? std::to_string(n / 1000) + "k" : std::to_string(n);
    // Brute force: the oracle of the exact answers, and the time a linear scan takes.
    std::vector<std::size_t> truth(queries);
    const double brute_s = compare::time_s([&] {
      for (std::size_t i = 0; i < queries; ++i) {
        double best = INFINITY;
        for (std::size_t j = 0; j < n; ++j) {
          double d = 0;
          for (std::size_t a = 0; a < dim; ++a) d += double(q[i * dim + a] - rows[j * dim + a]) * (q[i * dim + a] - rows[j * dim + a]);
          if (d < best) best = d, truth[i] = j;
        }
      }
    }) / double(queries);
    for (double eps : {0.0, 1.0}) {
      std::size_t agree = 0;
      double worst = 1;
      const double query_s = compare::median_time_s(args.reps, [&] {
        agree = 0;
        for (std::size_t i = 0; i < queries; ++i) {
          const auto m = db->query_descriptor(std::span(q.data() + i * dim, dim), 5, eps);
          agree += m.front().id == truth[i];
          const auto t = db->descriptor(truth[i]);
          const double best = shape::histogram_distance(std::span(q.data() + i * dim, dim), t, shape::Metric::l2);
          if (best > 0) worst = std::max(worst, m.front().distance / best);
        }
      }) / double(queries);
      compare::Record("shape", "geods", "query_" + size + (eps > 0 ? "_approx" : ""), args.threads)
          .timing(build_s, query_s, 1, args.reps)
          .set("brute_s", brute_s)
          .set("shapes", static_cast<unsigned long long>(n))
          .set("nearest_agree", double(agree) / double(queries))
          .set("worst_ratio", worst)
          .print(eps == 0 ? agree == queries : worst <= 1 + eps + 1e-6);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  const compare::Args args = compare::parse_args(argc, argv);
  const compare::ThreadLimit limit(args.threads);
  for (const auto& [variant, mesh] : shape_bench::describe_meshes(args)) describe_variant(args, variant, mesh);
  if (args.wants("retrieval_d2")) retrieval_variant(args, "retrieval_d2", "d2");
  if (args.wants("retrieval_combined")) retrieval_variant(args, "retrieval_combined", "combined");
  if (args.wants("query")) query_variants(args);
  return 0;
}
