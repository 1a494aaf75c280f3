// Python bindings of geods::core: the exact predicates (on single points or
// on stacked arrays of points), the 3D convex hull and the thread limit.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "arrays.hpp"
#include "geods/core/convex_hull3.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/predicates.hpp"
#include "geods/core/simd_level.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

using DoubleArray = Rows<double>;

// Calls of a predicate with N points of dimension Dim, one row per call.
template <int Dim, std::size_t N>
struct PredicateArgs {
  std::array<DoubleArray, N> arrays;
  std::array<const double*, N> data{};
  py::ssize_t count = 0;  // rows
  bool single = true;     // every argument was one point (1-D)
};

template <int Dim, std::size_t N>
PredicateArgs<Dim, N> to_rows(const char* name, const std::array<py::object, N>& args) {
  static constexpr const char* kLetters = "abcde";
  PredicateArgs<Dim, N> rows;
  for (std::size_t i = 0; i < N; ++i) {
    DoubleArray a = DoubleArray::ensure(args[i]);  // null if not convertible
    auto arg = [&] { return std::string(name).append(": argument '").append(1, kLetters[i]).append("'"); };
    if (!a) throw Error(arg() + " is not a sequence or array of numbers");
    const bool point = a.ndim() == 1 && a.shape(0) == Dim;
    const bool stacked = a.ndim() == 2 && a.shape(1) == Dim;
    if (!point && !stacked)
      throw Error(arg() + " must be a point of " + std::to_string(Dim) + " coordinates or an (n, " +
                  std::to_string(Dim) + ") array");
    if (i == 0) {
      rows.single = point;
      rows.count = point ? 1 : a.shape(0);
    } else if (point != rows.single) {
      throw Error(std::string(name) + ": mix of single points and (n, " + std::to_string(Dim) +
                  ") arrays; pass all arguments in the same form");
    } else if (stacked && a.shape(0) != rows.count) {
      throw Error(arg() + " has " + std::to_string(a.shape(0)) + " rows, argument 'a' has " +
                  std::to_string(rows.count));
    }
    rows.data[i] = a.data();
    rows.arrays[i] = std::move(a);
  }
  return rows;
}

// Evaluates `predicate(p0, ..., pN-1)` row by row: a float for single points,
// else a float64 array of length n (computed in parallel without the GIL).
template <int Dim, std::size_t N, typename Predicate>
py::object evaluate(const char* name, const std::array<py::object, N>& args, Predicate predicate) {
  const PredicateArgs<Dim, N> rows = to_rows<Dim, N>(name, args);
  auto row = [&](py::ssize_t r) {
    std::array<const double*, N> p;
    for (std::size_t i = 0; i < N; ++i) p[i] = rows.data[i] + r * Dim;
    return std::apply(predicate, p);
  };
  if (rows.single) return py::float_(row(0));
  py::array_t<double> result(rows.count);
  double* out = result.mutable_data();
  {
    py::gil_scoped_release release;
    parallel_for_each_index(0, std::size_t(rows.count), [&](std::size_t r) { out[r] = row(py::ssize_t(r)); }, 4096);
  }
  return result;
}

}  // namespace

void bind_core(py::module_& m) {
  // geods.Error is a ValueError: bad arguments and bad input files alike.
  py::register_exception<Error>(m, "Error", PyExc_ValueError);

  m.def(
      "orient2d",
      [](py::object a, py::object b, py::object c) {
        return evaluate<2, 3>("orient2d", {a, b, c},
                              [](const double* pa, const double* pb, const double* pc) { return orient2d(pa, pb, pc); });
      },
      py::arg("a"), py::arg("b"), py::arg("c"),
      R"doc(Exact orientation of three 2D points.

Returns a float > 0 if a, b, c are in counter-clockwise order, < 0 if
clockwise, exactly 0 if collinear (about twice the signed triangle area; the
sign is exact for any finite input, NaN if an input is NaN or infinite).
Each argument is one point (length 2) or an (n, 2) array; with arrays, all
have the same n and the result is a float64 array of n values.)doc");

  m.def(
      "orient3d",
      [](py::object a, py::object b, py::object c, py::object d) {
        return evaluate<3, 4>("orient3d", {a, b, c, d},
                              [](const double* pa, const double* pb, const double* pc, const double* pd) {
                                return orient3d(pa, pb, pc, pd);
                              });
      },
      py::arg("a"), py::arg("b"), py::arg("c"), py::arg("d"),
      R"doc(Exact orientation of four 3D points.

Returns a float > 0 if d lies below the plane through a, b, c (which appear
counter-clockwise seen from above), < 0 above, exactly 0 if coplanar: the
determinant of the rows a - d, b - d, c - d (six times the signed volume).
Arguments are points (length 3) or (n, 3) arrays with the same n.)doc");

  m.def(
      "incircle",
      [](py::object a, py::object b, py::object c, py::object d) {
        return evaluate<2, 4>("incircle", {a, b, c, d},
                              [](const double* pa, const double* pb, const double* pc, const double* pd) {
                                return incircle(pa, pb, pc, pd);
                              });
      },
      py::arg("a"), py::arg("b"), py::arg("c"), py::arg("d"),
      R"doc(Exact in-circle test of four 2D points.

For counter-clockwise a, b, c: a float > 0 if d is inside their circle, < 0
outside, exactly 0 on it; the sign flips for clockwise a, b, c.
Arguments are points (length 2) or (n, 2) arrays with the same n.)doc");

  m.def(
      "insphere",
      [](py::object a, py::object b, py::object c, py::object d, py::object e) {
        return evaluate<3, 5>(
            "insphere", {a, b, c, d, e},
            [](const double* pa, const double* pb, const double* pc, const double* pd, const double* pe) {
              return insphere(pa, pb, pc, pd, pe);
            });
      },
      py::arg("a"), py::arg("b"), py::arg("c"), py::arg("d"), py::arg("e"),
      R"doc(Exact in-sphere test of five 3D points.

For a, b, c, d with orient3d(a, b, c, d) > 0: a float > 0 if e is inside
their sphere, < 0 outside, exactly 0 on it; the sign flips when
orient3d(a, b, c, d) < 0. Arguments are points (length 3) or (n, 3) arrays
with the same n.)doc");

  m.def(
      "convex_hull",
      [](const py::handle& points) {
        const std::vector<Vec3d> p = points_of<double, 3>(points, "convex_hull: points");
        ConvexHull3 hull;
        {
          py::gil_scoped_release release;
          hull = convex_hull3(p);
        }
        const std::span<const std::uint32_t> corners(hull.faces.empty() ? nullptr : hull.faces[0].data(),
                                                     3 * hull.faces.size());  // std::array rows are contiguous
        return py::make_tuple(index_array(hull.vertices), index_array(corners, {py::ssize_t(hull.faces.size()), 3}),
                              hull.dimension);
      },
      py::arg("points"),
      R"doc(Convex hull of (n, 3) points, exact (orient3d decides every side test).

Returns (vertices, faces, dimension): the indices of the points that are
corners of the hull (ascending), the (k, 3) triangles over point indices,
counter-clockwise seen from outside (empty unless dimension is 3), and the
affine dimension of the points (-1 for none, 0 equal, 1 collinear, 2 coplanar:
then vertices are the corners of the planar hull polygon). Raises geods.Error
for NaN or infinite coordinates.)doc");

  m.def("set_num_threads", &set_num_threads, py::arg("n"),
        "Limits the worker threads of every later parallel call; n <= 0 restores all cores.");
  m.def("num_threads", &num_threads, "The current limit on worker threads (all cores unless set_num_threads was called).");
  m.def("simd_level", [] { return simd_level_name(simd_level()); },
        "The SIMD level of the multi-versioned kernels (the BVH's ray and packet traversals, terrain's error rows, the signed distance grid's candidate search): "
        "'portable', 'avx', 'avx2' or 'avx512'; the best the CPU runs, capped by the environment variable GEODS_SIMD.");
  m.def("best_simd_level", [] { return simd_level_name(best_simd_level()); },
        "The highest SIMD level this CPU (and the build) runs: 'portable', 'avx', 'avx2' or 'avx512'.");
  m.def("set_simd_level", [](const std::string& level) { set_simd_level(parse_simd_level(level)); }, py::arg("level"),
        "Sets the SIMD level of later kernel calls (every thread): 'portable', 'avx', 'avx2' or 'avx512'. "
        "Raises ValueError for an unknown name or a level the CPU does not run. Every level gives the same results.");
}

}  // namespace geods::python
