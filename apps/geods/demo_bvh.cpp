// Demo step of the bvh module: the boxes of the top levels of the SAH
// hierarchy over the bunny (side view), and the statistics and tightness of
// every builder with every bounding volume.
#include <fmt/format.h>

#include <array>
#include <vector>

#include "demo.hpp"
#include "geods/bvh/triangle_bvh.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/io/svg.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

void run_bvh(const DemoContext& context, DemoResult& result) {
  const TriMesh bunny = io::read_mesh(context.data_dir / "bunny.ply");

  // The figure: triangles and the boxes of levels 1 to 3 of a binary SAH tree, projected on (x, y).
  bvh::BuildOptions options;
  options.arity = 2;
  Stopwatch build_watch;
  const bvh::TriangleBvh tree = bvh::TriangleBvh::build(bunny, options);
  result.timing("build binary SAH BVH (3674 triangles)", build_watch.seconds());
  const AABB3f bounds = bunny.bounds();
  const AABB2d view(Vec2d(bounds.lo[0], bounds.lo[1]), Vec2d(bounds.hi[0], bounds.hi[1]));
  io::SvgWriter svg(AABB2d(view.lo - Vec2d(0.05, 0.05), view.hi + Vec2d(0.05, 0.05)), 900);
  svg.title("Bounding boxes of the top levels of a SAH hierarchy over the bunny");
  for (const auto& t : bunny.triangles) {
    const std::array<Vec2d, 3> p = {Vec2d(bunny.vertices[t[0]][0], bunny.vertices[t[0]][1]),
                                    Vec2d(bunny.vertices[t[1]][0], bunny.vertices[t[1]][1]),
                                    Vec2d(bunny.vertices[t[2]][0], bunny.vertices[t[2]][1])};
    svg.polygon(p, {.stroke = "#bbbbbb", .stroke_width = 0.3});
  }
  const auto& nodes = tree.topology().nodes;
  const auto& boxes = std::get<FlatArray<AABB3f>>(tree.volumes());
  const std::array<const char*, 3> colours = {"#c0392b", "#2471a3", "#27ae60"};
  std::vector<int> level(nodes.size(), 0);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    for (std::uint32_t c = 0; c < nodes[i].num_children; ++c) level[nodes[i].first_child + c] = level[i] + 1;
    if (level[i] < 1 || level[i] > 3) continue;
    const AABB2d box(Vec2d(boxes[i].lo[0], boxes[i].lo[1]), Vec2d(boxes[i].hi[0], boxes[i].hi[1]));
    svg.rect(box, {.stroke = colours[level[i] - 1], .stroke_width = 3.0 - 0.7 * level[i], .opacity = 0.9});
  }
  svg.save(context.out_dir / "bvh_boxes.svg");
  result.figures.push_back({"bvh_boxes.svg", "Boxes of levels 1 (red), 2 (blue) and 3 (green) of the binary SAH "
                                             "tree, projected on the x-y plane; grey: the bunny's triangles"});

  // The table: every builder with every bounding volume (binary trees, leaf size 4).
  std::string table = "builder / volume: SAH cost, tightness by volume (Def. 4), by Hausdorff distance (Def. 3)\n";
  for (bvh::Builder builder : {bvh::Builder::sah, bvh::Builder::median, bvh::Builder::pca, bvh::Builder::bottom_up,
                               bvh::Builder::tiling, bvh::Builder::insertion, bvh::Builder::boxtree}) {
    double build_s = 0;
    table += fmt::format("{:>10}:", bvh::to_string(builder));
    for (bvh::BoundingVolume bv : {bvh::BoundingVolume::aabb, bvh::BoundingVolume::sphere, bvh::BoundingVolume::kdop14,
                                   bvh::BoundingVolume::kdop26, bvh::BoundingVolume::obb}) {
      bvh::BuildOptions o;
      o.builder = builder;
      o.bv = bv;
      o.arity = 2;
      Stopwatch watch;
      const bvh::TriangleBvh h = bvh::TriangleBvh::build(bunny, o);
      build_s += watch.seconds();
      const bvh::BvhStats s = h.stats();
      table += fmt::format("  {} {:.1f} {:.2f} {:.3f}", bvh::to_string(bv), s.sah_cost, s.tightness_volume,
                           s.tightness_hausdorff);
      if (bv == bvh::BoundingVolume::aabb) result.stat(fmt::format("{} depth (AABB)", bvh::to_string(builder)), std::to_string(s.depth));
    }
    table += "\n";
    result.timing(fmt::format("build with {} (5 volumes)", bvh::to_string(builder)), build_s);
  }
  result.text =
      "Bounding volume hierarchies over the bunny's 3674 triangles. Below the figure: for each builder and bounding "
      "volume, the expected ray cost (SAH) and the two tightness measures of the seed (lower is tighter for "
      "Hausdorff; volume ratios near 1 mean children fill their parent).\n" +
      table;
  result.stat("triangles", std::to_string(bunny.num_triangles()));
}

const bool registered = register_demo_step({"bvh", "hierarchies", "Bounding volume hierarchies: builders and volumes", &run_bvh});

}  // namespace
}  // namespace geods::cli
