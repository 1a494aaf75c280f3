// geods' exact predicates (filtered, exact fallback) on the predicates comparison inputs.
#include <array>

#include "geods/core/predicates.hpp"
#include "predicates_driver.hpp"

namespace {

int sign(double v) { return (v > 0) - (v < 0); }

struct Geods {
  static constexpr const char* anchor = "geods";
  using P2 = std::array<double, 2>;
  using P3 = std::array<double, 3>;
  static P2 p2(const double* c) { return {c[0], c[1]}; }
  static P3 p3(const double* c) { return {c[0], c[1], c[2]}; }
  static int orient2d(const P2& a, const P2& b, const P2& c) { return sign(geods::orient2d(a.data(), b.data(), c.data())); }
  static int incircle(const P2& a, const P2& b, const P2& c, const P2& d) {
    return sign(geods::incircle(a.data(), b.data(), c.data(), d.data()));
  }
  static int orient3d(const P3& a, const P3& b, const P3& c, const P3& d) {
    return sign(geods::orient3d(a.data(), b.data(), c.data(), d.data()));
  }
  static int insphere(const P3& a, const P3& b, const P3& c, const P3& d, const P3& e) {
    return sign(geods::insphere(a.data(), b.data(), c.data(), d.data(), e.data()));
  }
};

}  // namespace

int main(int argc, char** argv) { return compare::predicates::run<Geods>(argc, argv); }
