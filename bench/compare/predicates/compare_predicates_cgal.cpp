// CGAL 5 Exact_predicates_inexact_constructions_kernel (interval filter + exact fallback).
// CGAL's orientation sign in 3D, and hence side_of_oriented_sphere, is the opposite of
// geods' (Shewchuk's) convention: both are negated so that the signs compare one to one.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "predicates_driver.hpp"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

struct Cgal {
  static constexpr const char* anchor = "cgal";
  using P2 = K::Point_2;
  using P3 = K::Point_3;
  static P2 p2(const double* c) { return P2(c[0], c[1]); }
  static P3 p3(const double* c) { return P3(c[0], c[1], c[2]); }
  static int orient2d(const P2& a, const P2& b, const P2& c) { return static_cast<int>(CGAL::orientation(a, b, c)); }
  static int incircle(const P2& a, const P2& b, const P2& c, const P2& d) {
    return static_cast<int>(CGAL::side_of_oriented_circle(a, b, c, d));
  }
  static int orient3d(const P3& a, const P3& b, const P3& c, const P3& d) {
    return -static_cast<int>(CGAL::orientation(a, b, c, d));
  }
  static int insphere(const P3& a, const P3& b, const P3& c, const P3& d, const P3& e) {
    return -static_cast<int>(CGAL::side_of_oriented_sphere(a, b, c, d, e));
  }
};

}  // namespace

int main(int argc, char** argv) { return compare::predicates::run<Cgal>(argc, argv); }
