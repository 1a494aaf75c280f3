// PCL's ESFEstimation (Wohlkinger & Vincze 2011: an ensemble of D2, D3 and A3 histograms,
// 640 values) on the shape workload: the same meshes as compare_shape_geods, 10,000 points
// sampled on each by geods' area-weighted sampler (the time includes the sampling), then ESF.
// Retrieval: leave-one-out ranking of the BlendSwap-CC-0 library by L1 and L2 distance of the
// ESF signatures (brute force), scored with geods' PSB measures. PCL links only into this program.
#include <pcl/features/esf.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>

#include "geods/shape/shape_distribution.hpp"
#include "shape_inputs.hpp"

namespace {

using namespace geods;
constexpr std::size_t kPoints = 10000;

std::vector<float> esf(const TriMesh& mesh) {
  const shape::SurfaceSampler sampler(mesh);
  Rng rng(0);
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->resize(kPoints);
  for (auto& p : *cloud) {
    const Vec3d s = sampler.sample(rng);
    p = pcl::PointXYZ(float(s.x()), float(s.y()), float(s.z()));
  }
  pcl::ESFEstimation<pcl::PointXYZ, pcl::ESFSignature640> estimation;
  estimation.setInputCloud(cloud);
  pcl::PointCloud<pcl::ESFSignature640> out;
  estimation.compute(out);
  return std::vector<float>(out[0].histogram, out[0].histogram + 640);
}

}  // namespace

int main(int argc, char** argv) {
  const compare::Args args = compare::parse_args(argc, argv);
  const compare::ThreadLimit limit(args.threads);
  for (const auto& [variant, mesh] : shape_bench::describe_meshes(args)) {
    std::vector<float> d;
    const double s = compare::median_time_s(args.reps, [&] { d = esf(mesh); });
    double sum = 0;
    for (float v : d) sum += v;
    compare::Record("shape", "pcl", variant, args.threads)
        .timing(0, s, 1, args.reps)
        .set("triangles", static_cast<unsigned long long>(mesh.triangles.size()))
        .print(sum > 0 && std::isfinite(sum));
  }
  if (args.wants("retrieval_d2") || args.wants("retrieval_combined")) {
    const shape_bench::Labelled c = shape_bench::read_collection(args);
    std::vector<std::vector<float>> d(c.meshes.size());
    const double build_s = compare::time_s([&] {
      for (std::size_t i = 0; i < c.meshes.size(); ++i) d[i] = esf(c.meshes[i]);  // ESF is single-threaded
    });
    for (const char* variant : {"retrieval_d2", "retrieval_combined"}) {
      if (!args.wants(variant)) continue;
      const shape::Metric metric = std::string(variant) == "retrieval_d2" ? shape::Metric::l2 : shape::Metric::l1;
      geods::shape::RetrievalScores s;
      const double query_s = compare::time_s([&] {
        s = shape_bench::score(c.labels, 5, [&](std::size_t i, std::size_t j) {
          return shape::histogram_distance(d[i], d[j], metric);
        });
      });
      compare::Record r("shape", "pcl", variant, args.threads);
      r.timing(build_s, query_s, c.meshes.size(), 1)
          .set("descriptor", std::string("esf640 ") + std::string(shape::metric_name(metric)))
          .set("dimension", 640);
      shape_bench::put_scores(r, s).print(s.queries > 0);
    }
  }
  return 0;
}
