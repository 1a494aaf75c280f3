#pragma once
// Library work that touches no Python object runs with the GIL released, so
// other Python threads go on meanwhile: `auto r = without_gil([&] { return work(); });`
#include <pybind11/pybind11.h>

#include <utility>

namespace geods::python {

template <typename Work>
auto without_gil(Work&& work) {
  pybind11::gil_scoped_release release;
  return std::forward<Work>(work)();
}

}  // namespace geods::python
