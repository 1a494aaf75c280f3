#include "geods/bsp/painter.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "geods/core/error.hpp"

namespace geods::bsp {

namespace {

using Point = ScreenBsp::Point;

// The one edge test of the module: s * ((b - a) x (p - a)) with d = b - a; >= 0 is inside.
inline double edge_value(const Point& a, const Point& d, double s, double x, double y) {
  return s * (d[0] * (y - a[1]) - d[1] * (x - a[0]));
}

double signed_area(std::span<const Point> p) {
  double area = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const Point& a = p[k];
    const Point& b = p[(k + 1) % p.size()];
    area += a[0] * b[1] - a[1] * b[0];
  }
  return area / 2;
}

// Keeps the part of a convex polygon where keep * value + margin >= 0 (Sutherland–Hodgman).
template <typename Value>
void clip(const std::vector<Point>& in, Value&& value, double keep, double margin, std::vector<Point>& out) {
  out.clear();
  const std::size_t n = in.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Point& p = in[k];
    const Point& q = in[(k + 1) % n];
    const double vp = keep * value(p) + margin, vq = keep * value(q) + margin;
    if (vp >= 0) out.push_back(p);
    if ((vp >= 0) != (vq >= 0)) {
      const double t = vp / (vp - vq);
      out.push_back({p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])});
    }
  }
  if (out.size() < 3) out.clear();
}

}  // namespace

// ---------------------------------------------------------------- ScreenBsp

// Margin of a line over a polygon: a bound far above the rounding of the edge test at any of
// its points, so that a pixel centre the test puts on one side is routed there.
double ScreenBsp::margin(const Line& l, const std::vector<Point>& poly) {
  double m = 0;
  for (const Point& p : poly) m = std::max(m, std::fabs(l.d[0] * (p[1] - l.a[1])) + std::fabs(l.d[1] * (p[0] - l.a[0])));
  return 1e-9 * m;
}

ScreenBsp::ScreenBsp(int width, int height) : width_(width), height_(height) {
  if (width <= 0 || height <= 0) throw Error("ScreenBsp: the screen size must be positive");
  nodes_.emplace_back();  // one free leaf
}

std::size_t ScreenBsp::insert(std::span<const Point> polygon, std::vector<std::uint32_t>& pixels) {
  for (const Point& p : polygon)
    if (!std::isfinite(p[0]) || !std::isfinite(p[1])) throw Error("ScreenBsp insert: a vertex is not finite");
  if (polygon.size() < 3) return 0;
  const double area = signed_area(polygon);
  if (!(area != 0)) return 0;
  const double s = area > 0 ? 1 : -1;
  std::vector<Line> edges;
  for (std::size_t k = 0; k < polygon.size(); ++k) {
    const Point& a = polygon[k];
    const Point& b = polygon[(k + 1) % polygon.size()];
    const Point d{b[0] - a[0], b[1] - a[1]};
    if (d[0] != 0 || d[1] != 0) edges.push_back({a, d, s});  // a zero edge is inside everywhere
  }
  const double W = width_, H = height_;
  // The part on the screen, a superset of polygon ∩ screen (with a margin: pieces only route
  // the polygon, pixels are tested exactly). For a polygon far larger than the screen,
  // clipping would lose the screen to cancellation: the piece is then the screen itself.
  std::vector<Point> piece(polygon.begin(), polygon.end()), tmp;
  bool huge = false;
  for (const Point& p : polygon) huge |= std::max(std::fabs(p[0]), std::fabs(p[1])) > 1e6 * (W + H);
  if (huge) piece = screen_rect();
  auto box_value = [](int axis, double bound, double sign) {
    return [=](const Point& p) { return sign * (p[std::size_t(axis)] - bound); };
  };
  for (int axis = 0; axis < 2 && !huge; ++axis)
    for (double sign : {1.0, -1.0}) {
      const double bound = sign > 0 ? 0 : (axis == 0 ? W : H);
      clip(piece, box_value(axis, bound, sign), 1, 1e-9 * (W + H), tmp);
      piece.swap(tmp);
      if (piece.empty()) return 0;
    }
  std::vector<Path> path;
  std::vector<std::vector<Point>> scratch;
  return visit(0, piece, edges, path, scratch, pixels);
}

std::size_t ScreenBsp::visit(std::uint32_t node, const std::vector<Point>& piece, std::span<const Line> edges,
                             std::vector<Path>& path, std::vector<std::vector<Point>>& scratch,
                             std::vector<std::uint32_t>& pixels) {
  // Down the tree while the piece lies on one side of the lines (no clipping needed).
  const std::size_t depth0 = path.size();
  std::size_t written = 0;
  for (;;) {
    const Cell c = nodes_[node];
    if (c.line == kNoIndex) break;
    const Line l = lines_[c.line];
    auto value = [&](const Point& p) { return edge_value(l.a, l.d, l.s, p[0], p[1]); };
    const double m = margin(l, piece);
    double lo = 1e300, hi = -1e300;
    for (const Point& p : piece) lo = std::min(lo, value(p)), hi = std::max(hi, value(p));
    const bool to_in = hi > -m, to_out = lo < m;
    if (to_in != to_out) {
      path.push_back({c.line, to_in});
      node = to_in ? c.in : c.out;
      continue;
    }
    if (to_in) {
      if (scratch.size() <= path.size()) scratch.resize(path.size() + 1);
      for (const bool in : {true, false}) {
        std::vector<Point>& sub = scratch[path.size()];
        clip(piece, value, in ? 1 : -1, m, sub);
        if (sub.empty()) continue;
        const std::vector<Point> part = sub;  // (scratch[path.size()] is reused below)
        path.push_back({c.line, in});
        written += visit(in ? c.in : c.out, part, edges, path, scratch, pixels);
        path.pop_back();
      }
    }
    path.resize(depth0);
    return written;
  }
  const std::size_t leaf_written = leaf(node, piece, edges, path, pixels);
  path.resize(depth0);
  return leaf_written;
}

std::size_t ScreenBsp::leaf(std::uint32_t node, const std::vector<Point>& piece, std::span<const Line> edges,
                            const std::vector<Path>& path, std::vector<std::uint32_t>& pixels) {
  const Cell c = nodes_[node];
  if (c.occupied) return 0;

  // A free leaf: the pixel centres of the cell inside the polygon.
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const Point& p : piece)
    x0 = std::min(x0, p[0]), x1 = std::max(x1, p[0]), y0 = std::min(y0, p[1]), y1 = std::max(y1, p[1]);
  // (clamped as doubles: huge or non-finite clipped coordinates never reach an int conversion)
  const int ix0 = int(std::max(0.0, std::floor(x0 - 1))), ix1 = int(std::min(double(width_ - 1), std::ceil(x1)));
  const int iy0 = int(std::max(0.0, std::floor(y0 - 1))), iy1 = int(std::min(double(height_ - 1), std::ceil(y1)));
  std::size_t written = 0;
  for (int y = iy0; y <= iy1; ++y)
    for (int x = ix0; x <= ix1; ++x) {
      const double cx = x + 0.5, cy = y + 0.5;
      bool inside = true;
      for (std::size_t k = 0; k < edges.size() && inside; ++k)
        inside = edge_value(edges[k].a, edges[k].d, edges[k].s, cx, cy) >= 0;
      for (std::size_t k = 0; k < path.size() && inside; ++k) {
        const Line& l = lines_[path[k].line];
        inside = (edge_value(l.a, l.d, l.s, cx, cy) >= 0) == path[k].in;
      }
      if (!inside) continue;
      pixels.push_back(std::uint32_t(y) * std::uint32_t(width_) + std::uint32_t(x));
      ++written;
    }
  // The cell (the screen clipped by the path's lines) and, without margins, the polygon's
  // part in it. A part of no pixel centre and of almost no area (a sliver the margins let
  // through along a line the polygon shares) leaves the leaf free.
  std::vector<Point> cell = screen_rect(), part = piece, sub;
  for (const Path& q : path) {
    const Line& l = lines_[q.line];
    auto value = [&](const Point& p) { return edge_value(l.a, l.d, l.s, p[0], p[1]); };
    if (!cell.empty()) clip(cell, value, q.in ? 1 : -1, 0, sub), cell.swap(sub);
    if (!part.empty()) clip(part, value, q.in ? 1 : -1, 0, sub), part.swap(sub);
  }
  if (written == 0 && (part.empty() || std::fabs(signed_area(part)) < 1e-6)) return 0;

  // Insert the polygon beneath the leaf: a chain of its edges that cross the cell, the
  // outside of each a free leaf, the inside of the last one occupied.
  std::uint32_t at = node;
  for (const Line& e : edges) {
    const double m = margin(e, cell);
    bool crosses = cell.empty();
    for (const Point& p : cell) crosses |= edge_value(e.a, e.d, e.s, p[0], p[1]) < m;
    if (!crosses) continue;
    const auto line = std::uint32_t(lines_.size());
    lines_.push_back(e);
    const auto in = std::uint32_t(nodes_.size());
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[at].line = line;
    nodes_[at].in = in;
    nodes_[at].out = in + 1;
    at = in;
  }
  nodes_[at].occupied = true;
  return written;
}

std::vector<Point> ScreenBsp::screen_rect() const {
  const double W = width_, H = height_;
  return {{0, 0}, {W, 0}, {W, H}, {0, H}};
}

bool ScreenBsp::occupied(double x, double y) const {
  std::uint32_t n = 0;
  while (nodes_[n].line != kNoIndex) {
    const Line& l = lines_[nodes_[n].line];
    n = edge_value(l.a, l.d, l.s, x, y) >= 0 ? nodes_[n].in : nodes_[n].out;
  }
  return nodes_[n].occupied;
}

double ScreenBsp::occupied_area() const {
  struct Item {
    std::uint32_t node;
    std::vector<Point> cell;
  };
  std::vector<Item> stack{{0, screen_rect()}};
  double area = 0;
  std::vector<Point> sub;
  while (!stack.empty()) {
    Item it = std::move(stack.back());
    stack.pop_back();
    const Cell& c = nodes_[it.node];
    if (c.line == kNoIndex) {
      if (c.occupied) area += std::fabs(signed_area(it.cell));
      continue;
    }
    const Line& l = lines_[c.line];
    auto value = [&](const Point& p) { return edge_value(l.a, l.d, l.s, p[0], p[1]); };
    for (const bool in : {true, false}) {
      clip(it.cell, value, in ? 1 : -1, 0, sub);
      if (!sub.empty()) stack.push_back({in ? c.in : c.out, sub});
    }
  }
  return area;
}

std::size_t ScreenBsp::depth() const {
  std::size_t depth = 0;
  std::vector<std::pair<std::uint32_t, std::size_t>> stack{{0, 0}};
  while (!stack.empty()) {
    const auto [n, d] = stack.back();
    stack.pop_back();
    depth = std::max(depth, d);
    if (nodes_[n].line != kNoIndex) stack.push_back({nodes_[n].in, d + 1}), stack.push_back({nodes_[n].out, d + 1});
  }
  return depth;
}

// ---------------------------------------------------------------- paint

PainterResult paint(const BspTree& tree, const PainterView& view, bool back_to_front) {
  if (view.width <= 0 || view.height <= 0) throw Error("paint: image size must be positive");
  const Vec3d fwd0 = view.target - view.eye;
  if (!(fwd0.norm() > 0) || !std::isfinite(fwd0.norm())) throw Error("paint: eye at the target or not finite");
  const Vec3d forward = fwd0.normalized();
  const Vec3d r0 = forward.cross(view.up);
  if (!(r0.norm() > 1e-12)) throw Error("paint: up vector parallel to the view direction");
  if (!(view.vertical_fov_deg > 0 && view.vertical_fov_deg < 180)) throw Error("paint: field of view outside (0, 180)");
  const Vec3d right = r0.normalized(), up = right.cross(forward);
  const double h = std::tan(0.5 * view.vertical_fov_deg * std::numbers::pi / 180);
  const double aspect = double(view.width) / double(view.height);
  const int W = view.width, H = view.height;

  // Frustum corners for the tree's culling: the eye and four far corners.
  const double far = 1e3 * (1 + (view.target - view.eye).norm());
  std::vector<Vec3d> frustum{view.eye};
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0}) frustum.push_back(view.eye + far * (forward + sx * h * aspect * right + sy * h * up));

  PainterResult res;
  res.triangle.assign(std::size_t(W) * std::size_t(H), kNoIndex);
  std::optional<ScreenBsp> screen;
  if (!back_to_front) screen.emplace(W, H);
  const std::vector<std::uint32_t> order = tree.visibility_order(view.eye, back_to_front, frustum);
  res.fragments = order.size();
  std::vector<Point> p;
  std::vector<std::uint32_t> pixels;
  for (const std::uint32_t fi : order) {
    const Polygon& f = tree.fragments()[fi];
    p.clear();
    bool behind = false;
    for (std::size_t k = 0; k < f.size(); ++k) {
      const Vec3d w = tree.grid().to_world(tree.planes().point(f.vertex(k)));
      const Vec3d d = w - view.eye;
      const double z = d.dot(forward);
      if (!(z > 1e-9)) {
        behind = true;
        break;
      }
      const double sx = d.dot(right) / (z * h * aspect), sy = d.dot(up) / (z * h);
      p.push_back({(sx + 1) * 0.5 * W, (1 - sy) * 0.5 * H});
    }
    if (behind || p.size() < 3) continue;  // (the camera is outside the scene in the demo and tests)
    if (!back_to_front) {
      // Front to back: only the still-free parts, each pixel once.
      pixels.clear();
      screen->insert(p, pixels);
      for (const std::uint32_t pix : pixels) res.triangle[pix] = f.source;
      res.pixel_writes += pixels.size();
      continue;
    }
    const double area = signed_area(p);
    if (area == 0) continue;
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (const Point& q : p) x0 = std::min(x0, q[0]), x1 = std::max(x1, q[0]), y0 = std::min(y0, q[1]), y1 = std::max(y1, q[1]);
    const int ix0 = int(std::max(0.0, std::floor(x0 - 0.5))), ix1 = int(std::min(double(W - 1), std::ceil(x1 - 0.5)));
    const int iy0 = int(std::max(0.0, std::floor(y0 - 0.5))), iy1 = int(std::min(double(H - 1), std::ceil(y1 - 0.5)));
    const double s = area > 0 ? 1 : -1;
    for (int y = iy0; y <= iy1; ++y)
      for (int x = ix0; x <= ix1; ++x) {
        bool inside = true;
        for (std::size_t k = 0; k < p.size() && inside; ++k) {
          const Point& a = p[k];
          const Point& b = p[(k + 1) % p.size()];
          inside = edge_value(a, {b[0] - a[0], b[1] - a[1]}, s, x + 0.5, y + 0.5) >= 0;
        }
        if (!inside) continue;
        res.triangle[std::size_t(y) * std::size_t(W) + std::size_t(x)] = f.source;
        ++res.pixel_writes;
      }
  }
  if (screen) res.screen_nodes = screen->nodes();
  return res;
}

}  // namespace geods::bsp
