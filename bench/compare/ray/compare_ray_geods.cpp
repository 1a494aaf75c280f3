// geods' BVH on the ray comparison (geods_bvh_ray.hpp).
#include "geods_bvh_ray.hpp"

int main(int argc, char** argv) { return compare::ray::run<compare::ray::Geods>(argc, argv); }
