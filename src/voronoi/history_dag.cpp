// The history DAG: nodes appended as the core splits and flips, located by descent.
#include "history_dag.hpp"

namespace geods::voronoi {
namespace {
constexpr std::uint32_t kNone = DelaunayCore::none;
constexpr std::uint32_t kGhost = DelaunayCore::ghost;
}  // namespace

HistoryDag::HistoryDag(const DelaunayCore& core, std::size_t points) : core_(&core) {
  const std::uint32_t a = core.vert[0], b = core.vert[1], c = core.vert[2];
  center_ = (core.at(a) + core.at(b) + core.at(c)) / 3;
  usable_ = orient2d(core.at(a), core.at(b), center_) > 0 && orient2d(core.at(b), core.at(c), center_) > 0 &&
            orient2d(core.at(c), core.at(a), center_) > 0;
  if (!usable_) return;
  nodes_.reserve(9 * points + 4);
  for (std::uint32_t t = 0; t < 4; ++t) add_node(t);
}

std::uint32_t HistoryDag::add_node(std::uint32_t t) {
  const std::uint32_t id = std::uint32_t(nodes_.size());
  const auto& vert = core_->vert;
  nodes_.push_back({{vert[3 * t], vert[3 * t + 1], vert[3 * t + 2]}, {kNone, kNone, kNone}, t});
  if (triangle_node_.size() <= t) triangle_node_.resize(t + 1, kNone);
  triangle_node_[t] = id;
  return id;
}

void HistoryDag::split_triangle(std::uint32_t t, std::uint32_t t1, std::uint32_t t2) {
  const std::uint32_t parent = triangle_node_[t];
  const std::uint32_t children[3] = {add_node(t), add_node(t1), add_node(t2)};
  std::copy(children, children + 3, nodes_[parent].child);
}

void HistoryDag::split_edge(std::uint32_t e, std::uint32_t twin, std::uint32_t t1, std::uint32_t t2) {
  const std::uint32_t parent_e = triangle_node_[e / 3], parent_t = triangle_node_[twin / 3];
  const std::uint32_t c0 = add_node(e / 3), c1 = add_node(t1);
  nodes_[parent_e].child[0] = c0, nodes_[parent_e].child[1] = c1;
  const std::uint32_t c2 = add_node(twin / 3), c3 = add_node(t2);
  nodes_[parent_t].child[0] = c2, nodes_[parent_t].child[1] = c3;
}

void HistoryDag::flip(std::uint32_t e, std::uint32_t f) {
  const std::uint32_t parent_e = triangle_node_[e / 3], parent_f = triangle_node_[f / 3];
  const std::uint32_t c0 = add_node(e / 3), c1 = add_node(f / 3);
  for (std::uint32_t parent : {parent_e, parent_f}) nodes_[parent].child[0] = c0, nodes_[parent].child[1] = c1;
}

bool HistoryDag::contains(std::uint32_t node, const Vec2d& q) const {
  const std::uint32_t* v = nodes_[node].vertex;
  const DelaunayCore& core = *core_;
  if (((v[0] | v[1] | v[2]) & DelaunayCore::ghost_bit) == 0)
    return orient2d(core.at(v[0]), core.at(v[1]), q) >= 0 && orient2d(core.at(v[1]), core.at(v[2]), q) >= 0 &&
           orient2d(core.at(v[2]), core.at(v[0]), q) >= 0;
  // Ghost triangle (x, y, ghost), hull edge y -> x: the part of the cone from
  // the centre between the rays through y and x that lies beyond the edge.
  const int g = v[0] == kGhost ? 0 : v[1] == kGhost ? 1 : 2;
  const Vec2d &x = core.at(v[(g + 1) % 3]), &y = core.at(v[(g + 2) % 3]);
  return orient2d(x, y, q) >= 0 && orient2d(center_, y, q) >= 0 && orient2d(center_, x, q) <= 0;
}

std::uint32_t HistoryDag::start(const Vec2d& q) const {
  std::uint32_t node = kNone;
  for (std::uint32_t root = 0; root < 4 && node == kNone; ++root)
    if (contains(root, q)) node = root;
  if (node == kNone) return core_->last_triangle;
  for (;;) {
    const Node& h = nodes_[node];
    if (h.child[0] == kNone) return h.triangle;  // a leaf: the walk finishes from here in O(1)
    std::uint32_t next_node = kNone;
    for (std::uint32_t c : h.child)
      if (c != kNone && contains(c, q)) {
        next_node = c;
        break;
      }
    if (next_node == kNone) return core_->last_triangle;  // not reached: the children cover their parent
    node = next_node;
  }
}

}  // namespace geods::voronoi
