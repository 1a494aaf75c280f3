#include "geods/io/svg.hpp"

#include <fmt/format.h>

#include <cmath>

#include "file_util.hpp"
#include "geods/io/output.hpp"

namespace geods::io {

namespace {

void require_finite(const Vec2d& p) {
  if (!p.allFinite()) throw Error("svg: non-finite coordinate");
}

}  // namespace

std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

SvgWriter::SvgWriter(const AABB2d& view, double width, double margin) : view_(view), width_(width), margin_(margin) {
  if (view.empty() || !view.lo.allFinite() || !view.hi.allFinite()) throw Error("svg: the view box is empty or not finite");
  if (!(width > 2 * margin) || !(margin >= 0) || !std::isfinite(width))
    throw Error("svg: width must exceed twice the margin");
  Vec2d extent = view.extent();
  // A view of zero width or height (all points on a line) still gets a finite scale.
  if (extent.x() <= 0 && extent.y() <= 0) extent = Vec2d::Ones();
  else if (extent.x() <= 0) extent.x() = extent.y();
  scale_ = (width - 2 * margin) / extent.x();
  height_ = extent.y() * scale_ + 2 * margin;
}

Vec2d SvgWriter::map(const Vec2d& p) const {
  require_finite(p);
  return {margin_ + (p.x() - view_.lo.x()) * scale_, margin_ + (view_.hi.y() - p.y()) * scale_};
}

std::string SvgWriter::attributes(const SvgStyle& style, bool filled) {
  std::string a = fmt::format(R"( stroke="{}" stroke-width="{}")", xml_escape(style.stroke), style.stroke_width);
  a += fmt::format(R"( fill="{}")", filled ? xml_escape(style.fill) : "none");
  if (style.opacity != 1.0) a += fmt::format(R"( opacity="{}")", style.opacity);
  return a;
}

void SvgWriter::point(const Vec2d& p, const SvgStyle& style) {
  const Vec2d q = map(p);
  // A point is a dot: filled with its fill colour, or its stroke colour if it has none.
  const std::string colour = xml_escape(style.fill != "none" ? style.fill : style.stroke);
  body_ += fmt::format(R"(<circle cx="{:.2f}" cy="{:.2f}" r="{}" fill="{}" stroke="none")", q.x(), q.y(), style.radius, colour);
  if (style.opacity != 1.0) body_ += fmt::format(R"( opacity="{}")", style.opacity);
  body_ += "/>\n";
}

void SvgWriter::points(std::span<const Vec2d> ps, const SvgStyle& style) {
  for (const Vec2d& p : ps) point(p, style);
}

void SvgWriter::segment(const Vec2d& a, const Vec2d& b, const SvgStyle& style) {
  const Vec2d p = map(a), q = map(b);
  body_ += fmt::format(R"(<line x1="{:.2f}" y1="{:.2f}" x2="{:.2f}" y2="{:.2f}"{}/>)", p.x(), p.y(), q.x(), q.y(),
                       attributes(style, false)) + "\n";
}

void SvgWriter::polyline(std::span<const Vec2d> ps, const SvgStyle& style) {
  std::string pts;
  for (const Vec2d& p : ps) {
    const Vec2d q = map(p);
    pts += fmt::format("{:.2f},{:.2f} ", q.x(), q.y());
  }
  body_ += fmt::format(R"(<polyline points="{}"{} stroke-linejoin="round"/>)", pts, attributes(style, false)) + "\n";
}

void SvgWriter::polygon(std::span<const Vec2d> ps, const SvgStyle& style) {
  std::string pts;
  for (const Vec2d& p : ps) {
    const Vec2d q = map(p);
    pts += fmt::format("{:.2f},{:.2f} ", q.x(), q.y());
  }
  body_ += fmt::format(R"(<polygon points="{}"{} stroke-linejoin="round"/>)", pts, attributes(style, true)) + "\n";
}

void SvgWriter::circle(const Vec2d& center, double radius, const SvgStyle& style) {
  const Vec2d c = map(center);
  if (!std::isfinite(radius) || radius < 0) throw Error("svg: circle radius must be finite and non-negative");
  body_ += fmt::format(R"(<circle cx="{:.2f}" cy="{:.2f}" r="{:.2f}"{}/>)", c.x(), c.y(), radius * scale_,
                       attributes(style, true)) + "\n";
}

void SvgWriter::rect(const AABB2d& box, const SvgStyle& style) {
  const Vec2d a = map({box.lo.x(), box.hi.y()}), b = map({box.hi.x(), box.lo.y()});
  body_ += fmt::format(R"(<rect x="{:.2f}" y="{:.2f}" width="{:.2f}" height="{:.2f}"{}/>)", a.x(), a.y(),
                       std::max(0.0, b.x() - a.x()), std::max(0.0, b.y() - a.y()), attributes(style, true)) + "\n";
}

void SvgWriter::label(const Vec2d& p, const std::string& text, const SvgStyle& style) {
  const Vec2d q = map(p);
  // Text is drawn in its fill colour, or its stroke colour if it has none.
  const std::string colour = xml_escape(style.fill != "none" ? style.fill : style.stroke);
  body_ += fmt::format(R"(<text x="{:.2f}" y="{:.2f}" font-family="sans-serif" font-size="{}" fill="{}">{}</text>)",
                       q.x(), q.y(), style.font_size, colour, xml_escape(text)) + "\n";
}

void SvgWriter::title(const std::string& text) { title_ = text; }

std::string SvgWriter::str() const {
  std::string s = fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0:.0f}\" height=\"{1:.0f}\" viewBox=\"0 0 {0:.2f} {1:.2f}\">\n",
      width_, height_);
  if (!title_.empty()) s += "<title>" + xml_escape(title_) + "</title>\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s += body_;
  s += "</svg>\n";
  return s;
}

void SvgWriter::save(const std::filesystem::path& path) const {
  check_output_extension(path, OutputKind::svg);
  detail::write_file(path, str());
}

}  // namespace geods::io
