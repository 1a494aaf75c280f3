#pragma once
// One bind function per library module, called from module.cpp.
#include <pybind11/pybind11.h>

namespace geods::python {

void bind_core(pybind11::module_& m);  // bind_core.cpp: predicates, threads
void bind_io(pybind11::module_& m);    // bind_io.cpp: meshes, volumes, points
void bind_spatial(pybind11::module_& m);  // bind_spatial.cpp: k-d tree
void bind_bvh(pybind11::module_& m);  // bind_bvh.cpp: bounding volume hierarchy
void bind_dynamic(pybind11::module_& m);  // bind_dynamic.cpp: dynamic k-d tree
void bind_quadtree(pybind11::module_& m);  // bind_quadtree.cpp: quadtree, octree
void bind_delaunay(pybind11::module_& m);  // bind_delaunay.cpp: Delaunay triangulation
void bind_ray(pybind11::module_& m);  // bind_ray.cpp: ray accelerators, render
void bind_iso(pybind11::module_& m);       // bind_iso.cpp: isosurfaces, min/max octree
void bind_voronoi(pybind11::module_& m);  // bind_voronoi.cpp: Voronoi2, MetricVoronoi, emst, circles
void bind_texture(pybind11::module_& m);  // bind_texture.cpp: texture synthesis, hole filling
void bind_field(pybind11::module_& m);    // bind_field.cpp: distance transform
void bind_shape(pybind11::module_& m);    // bind_shape.cpp: shape distributions, ShapeDatabase
void bind_bsp(pybind11::module_& m);      // bind_bsp.cpp: BSP trees, boolean operations

}  // namespace geods::python
