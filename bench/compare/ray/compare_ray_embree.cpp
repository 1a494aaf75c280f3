// Embree 3 on the ray comparison (embree_ray.hpp); compiled a second time as
// compare_ray_embree_robust (RTC_SCENE_FLAG_ROBUST).
#include "embree_ray.hpp"

int main(int argc, char** argv) {
  const compare::Args args = compare::parse_args(argc, argv);
  compare::ray::Embree::threads = args.threads;
  return compare::ray::run<compare::ray::Embree>(argc, argv);
}
