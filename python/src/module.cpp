// The extension module geods._geods: each library module adds its bindings in one line.
#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(_geods, m) {
  m.doc() = "geods: geometric data structures for computer graphics";
  m.attr("__version__") = GEODS_VERSION;
  geods::python::bind_core(m);
  geods::python::bind_io(m);
  geods::python::bind_spatial(m);
  geods::python::bind_bvh(m);
  geods::python::bind_dynamic(m);
  geods::python::bind_quadtree(m);
  geods::python::bind_voronoi(m);
  geods::python::bind_generalized_voronoi(m);
  geods::python::bind_delaunay(m);
  geods::python::bind_ray(m);
  geods::python::bind_iso(m);
  geods::python::bind_texture(m);
  geods::python::bind_field(m);
  geods::python::bind_terrain(m);
  geods::python::bind_field_modeling(m);
  geods::python::bind_adf(m);
  geods::python::bind_shape(m);
  geods::python::bind_collide(m);
  geods::python::bind_segment_voronoi(m);
  geods::python::bind_bsp(m);
}
