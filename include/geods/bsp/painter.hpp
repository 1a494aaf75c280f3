#pragma once
// Rendering without a z-buffer (seed §3.1): the fragments of a BspTree rasterized in
// visibility order through a pinhole camera (the conventions of ray::Camera: pixel
// (x + 0.5, y + 0.5) is sampled, rows top to bottom). Back to front (the painter's
// algorithm) overwrites. Front to back runs each projected fragment through a 2D BSP of
// the screen whose leaves are free or occupied (ScreenBsp): the parts that reach free
// leaves are inserted beneath them and only those parts are rasterized, so each pixel is
// written once. Fragments on the far side of every frustum corner's plane are skipped by
// the tree.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "geods/bsp/bsp_tree.hpp"

namespace geods::bsp {

/// The 2D screen BSP of §3.1 over the screen [0, width] x [0, height]: inner nodes hold the
/// lines of projected polygon edges, leaves are free or occupied; initially one free leaf.
/// A point lies on the inside of a polygon's edge a->b when
/// s * ((b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x)) >= 0 (s the polygon's orientation),
/// evaluated in doubles; a point descends into the inside child under the same test, so the
/// pixel centres of an occupied leaf are exactly those of the polygon part inserted there.
class ScreenBsp {
 public:
  using Point = std::array<double, 2>;
  /// Throws geods::Error unless width, height > 0.
  ScreenBsp(int width, int height);
  /// Runs a convex polygon (screen coordinates, vertices in order, either orientation) down
  /// the tree: a part reaching an occupied leaf is dropped; a part reaching a free leaf is
  /// inserted beneath it (the leaf is split by the polygon's edges that cross it, the inside
  /// becomes occupied) and the pixels whose centres lie in that part are appended to `pixels`
  /// (row-major index y * width + x). Returns how many were appended. A polygon of zero area
  /// changes nothing; non-finite coordinates throw geods::Error.
  std::size_t insert(std::span<const Point> polygon, std::vector<std::uint32_t>& pixels);
  /// Whether (x, y) lies in an occupied cell.
  bool occupied(double x, double y) const;
  /// Area of the occupied cells (inside the screen rectangle).
  double occupied_area() const;
  std::size_t nodes() const { return nodes_.size(); }
  std::size_t depth() const;
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  struct Line {
    Point a, d;  // a point and the direction b - a
    double s;    // orientation: the inside is s * cross >= 0
  };
  struct Cell {
    std::uint32_t line = kNoIndex;  // kNoIndex: a leaf
    std::uint32_t in = kNoIndex, out = kNoIndex;
    bool occupied = false;
  };
  struct Path {
    std::uint32_t line;
    bool in;
  };
  std::size_t visit(std::uint32_t node, const std::vector<Point>& piece, std::span<const Line> edges,
                    std::vector<Path>& path, std::vector<std::vector<Point>>& scratch, std::vector<std::uint32_t>& pixels);
  std::size_t leaf(std::uint32_t node, const std::vector<Point>& piece, std::span<const Line> edges,
                   const std::vector<Path>& path, std::vector<std::uint32_t>& pixels);
  std::vector<Point> screen_rect() const;
  static double margin(const Line& l, const std::vector<Point>& poly);

  int width_, height_;
  std::vector<Line> lines_;
  std::vector<Cell> nodes_;
};

struct PainterView {
  Vec3d eye{0, 0, 3}, target{0, 0, 0}, up{0, 1, 0};
  double vertical_fov_deg = 40;
  int width = 256, height = 256;
};

struct PainterResult {
  std::vector<std::uint32_t> triangle;  // per pixel (row-major from the top): input triangle, kNoIndex for none
  std::size_t pixel_writes = 0;         // writes to the image (front to back: one per covered pixel)
  std::size_t fragments = 0;            // fragments listed by the traversal
  std::size_t screen_nodes = 0;         // front to back: nodes of the screen BSP at the end
};

/// Throws geods::Error for a degenerate view (eye at target, up parallel to the view, size 0).
PainterResult paint(const BspTree& tree, const PainterView& view, bool back_to_front = true);

}  // namespace geods::bsp
