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
void bind_generalized_voronoi(pybind11::module_& m);  // bind_generalized_voronoi.cpp: power, farthest, k-th order
void bind_texture(pybind11::module_& m);  // bind_texture.cpp: texture synthesis, hole filling
void bind_field(pybind11::module_& m);    // bind_field.cpp: distance transform
void bind_terrain(pybind11::module_& m);  // bind_terrain.cpp: terrain level of detail
void bind_field_modeling(pybind11::module_& m);  // bind_field_modeling.cpp: projection, CSG, morph
void bind_adf(pybind11::module_& m);      // bind_adf.cpp: adaptively sampled distance fields
void bind_shape(pybind11::module_& m);    // bind_shape.cpp: shape distributions, ShapeDatabase
void bind_collide(pybind11::module_& m);  // bind_collide.cpp: collision detection, mesh distance
void bind_segment_voronoi(pybind11::module_& m);  // bind_segment_voronoi.cpp: SegmentVoronoi, MotionPlanner, plan_path
void bind_bsp(pybind11::module_& m);      // bind_bsp.cpp: BSP trees, boolean operations

}  // namespace geods::python
