#pragma once
// An SVG writer for 2D figures in world coordinates (y up).
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "geods/core/aabb.hpp"

namespace geods::io {

struct SvgStyle {
  std::string stroke = "black";  // any SVG colour; "none" for no outline
  std::string fill = "none";
  double stroke_width = 1.0;     // in pixels, independent of the world scale
  double opacity = 1.0;
  double radius = 2.0;           // in pixels, for points
  double font_size = 12.0;       // in pixels, for labels
};

/// Escapes & < > " ' for XML and HTML text and attribute values.
std::string xml_escape(std::string_view text);

/// Collects shapes given in world coordinates and maps `view` onto a picture
/// `width` pixels wide (height by the aspect ratio), flipping y so up is up.
/// Coordinates are converted to pixels here, so stroke widths, point radii and
/// font sizes are in pixels whatever the world scale. Points and labels are
/// drawn in their fill colour, or their stroke colour if the fill is "none".
/// Throws geods::Error for an empty or non-finite view and non-finite shapes.
class SvgWriter {
 public:
  SvgWriter(const AABB2d& view, double width = 800, double margin = 10);

  void point(const Vec2d& p, const SvgStyle& style = {});
  void points(std::span<const Vec2d> ps, const SvgStyle& style = {});
  void segment(const Vec2d& a, const Vec2d& b, const SvgStyle& style = {});
  void polyline(std::span<const Vec2d> ps, const SvgStyle& style = {});
  void polygon(std::span<const Vec2d> ps, const SvgStyle& style = {});
  void circle(const Vec2d& center, double radius, const SvgStyle& style = {});  // radius in world units
  void rect(const AABB2d& box, const SvgStyle& style = {});
  void label(const Vec2d& p, const std::string& text, const SvgStyle& style = {});
  void title(const std::string& text);  // the picture's <title>

  double width() const { return width_; }
  double height() const { return height_; }
  std::string str() const;
  void save(const std::filesystem::path& path) const;  // a .svg file, or "-" for standard output

 private:
  Vec2d map(const Vec2d& p) const;
  static std::string attributes(const SvgStyle& style, bool filled);

  AABB2d view_;
  double width_, height_, margin_, scale_;
  std::string title_;
  std::string body_;
};

}  // namespace geods::io
