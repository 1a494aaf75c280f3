// Python bindings of geods::field: the Euclidean distance transform.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/field/edt.hpp"
#include "without_gil.hpp"

namespace geods::python {
namespace {

// A 1-, 2- or 3-D array as a mask volume (nonzero = foreground; C order, the
// last axis x) and the array's shape.
Grid3<std::uint8_t> mask_from(const py::object& mask, std::vector<py::ssize_t>& shape) {
  const py::module_ np = py::module_::import("numpy");
  const py::array a = np.attr("asarray")(mask);
  if (a.ndim() < 1 || a.ndim() > 3) throw Error("edt: the mask must be a 1-, 2- or 3-D array");
  const char kind = a.dtype().kind();
  if (kind != 'b' && kind != 'i' && kind != 'u' && kind != 'f')
    throw Error("edt: the mask must hold numbers or booleans, got " + py::cast<std::string>(py::repr(a.dtype())));
  if (kind == 'f' && py::cast<bool>(np.attr("isnan")(a).attr("any")())) throw Error("edt: the mask holds NaN");
  const Rows<std::uint8_t> flags = Rows<std::uint8_t>::ensure(np.attr("not_equal")(a, 0));
  shape.assign(a.shape(), a.shape() + a.ndim());
  Grid3<std::uint8_t> g;
  for (py::ssize_t d = 0; d < a.ndim(); ++d) g.dims[std::size_t(d)] = std::size_t(a.shape(a.ndim() - 1 - d));
  for (py::ssize_t d = a.ndim(); d < 3; ++d) g.dims[std::size_t(d)] = 1;
  g.data.assign(flags.data(), flags.data() + flags.size());
  return g;
}

py::object edt_py(const py::object& mask, const py::object& spacing, bool return_indices, bool squared) {
  std::vector<py::ssize_t> shape;
  const Grid3<std::uint8_t> grid = mask_from(mask, shape);
  field::EdtRequest request;
  request.squared = squared;
  request.features = return_indices;
  if (!spacing.is_none()) {
    std::array<double, 3> s{1, 1, 1};
    if (py::isinstance<py::float_>(spacing) || py::isinstance<py::int_>(spacing)) {
      s.fill(py::cast<double>(spacing));
    } else {
      const auto values = py::cast<std::vector<double>>(spacing);
      if (values.size() != shape.size())
        throw Error("edt: spacing needs one value per axis (x first), " + std::to_string(shape.size()) +
                    " for this mask, got " + std::to_string(values.size()));
      std::copy(values.begin(), values.end(), s.begin());
    }
    request.spacing = s;
  }
  const field::EdtResult r = without_gil([&] { return field::edt(grid.view(), request); });
  py::array_t<double> distance = copy_array(r.distance.data.data(), shape);
  if (!return_indices) return distance;
  return py::make_tuple(distance, index_array(r.features, shape));
}

}  // namespace

void bind_field(py::module_& m) {
  m.def("edt", &edt_py, py::arg("mask"), py::arg("spacing") = py::none(), py::arg("return_indices") = false,
        py::arg("squared") = false,
        "Exact Euclidean distance transform of a 1-, 2- or 3-D mask (nonzero = foreground): per sample, the\n"
        "distance to the nearest zero sample (0 on zeros, inf if there is none), float64 of the mask's shape.\n"
        "spacing: one number, or one per axis in geods order (x first: (sx, sy, sz) for a (nz, ny, nx) mask,\n"
        "the reverse of scipy's `sampling`). return_indices: also the flat (C-order) index of the nearest\n"
        "zero sample (int64, -1 if none); np.unravel_index(i, mask.shape) gives its coordinates.\n"
        "squared: squared distances. Felzenszwalb-Huttenlocher, parallel; equal to brute force bit for bit\n"
        "with integer spacings.");
}

}  // namespace geods::python
