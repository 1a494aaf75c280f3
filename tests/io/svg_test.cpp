#include "geods/io/svg.hpp"

#include "io_test_util.hpp"

namespace geods::io {
namespace {

TEST(Svg, MapsWorldToPixelsWithYUp) {
  SvgWriter svg(AABB2d(Vec2d(0, 0), Vec2d(10, 5)), 220, 10);
  EXPECT_DOUBLE_EQ(svg.width(), 220);
  EXPECT_DOUBLE_EQ(svg.height(), 120);  // 5 world units at 20 px each + margins
  svg.segment(Vec2d(0, 0), Vec2d(10, 5), {.stroke = "red", .stroke_width = 3});
  svg.circle(Vec2d(5, 2.5), 1.0);
  svg.rect(AABB2d(Vec2d(1, 1), Vec2d(2, 3)), {.fill = "blue"});
  svg.point(Vec2d(0, 5), {.stroke = "green", .radius = 4});
  const std::vector<Vec2d> poly = {{0, 0}, {1, 0}, {0, 1}};
  svg.polygon(poly, {.fill = "#ff0"});
  svg.polyline(poly);
  const std::string s = svg.str();
  EXPECT_NE(s.find(R"(<line x1="10.00" y1="110.00" x2="210.00" y2="10.00" stroke="red" stroke-width="3")"), std::string::npos) << s;
  EXPECT_NE(s.find(R"(<circle cx="110.00" cy="60.00" r="20.00")"), std::string::npos) << s;
  EXPECT_NE(s.find(R"(<rect x="30.00" y="50.00" width="20.00" height="40.00")"), std::string::npos) << s;
  EXPECT_NE(s.find(R"(<circle cx="10.00" cy="10.00" r="4" fill="green")"), std::string::npos) << s;
  EXPECT_NE(s.find(R"(fill="#ff0")"), std::string::npos);
  EXPECT_NE(s.find("<polyline"), std::string::npos);
  EXPECT_EQ(s.rfind("</svg>\n"), s.size() - 7);
}

TEST(Svg, EscapesTextAndSaves) {
  SvgWriter svg(AABB2d(Vec2d(0, 0), Vec2d(1, 1)));
  svg.title("a < b & \"c\"");
  svg.label(Vec2d(0.5, 0.5), "<script>&'");
  const std::string s = svg.str();
  EXPECT_NE(s.find("<title>a &lt; b &amp; &quot;c&quot;</title>"), std::string::npos) << s;
  EXPECT_NE(s.find("&lt;script&gt;&amp;&apos;</text>"), std::string::npos) << s;
  EXPECT_EQ(s.find("<script>"), std::string::npos);
  test::TempDir dir;
  svg.save(dir / "f.svg");
  EXPECT_EQ(test::read_text(dir / "f.svg"), s);
  EXPECT_THROW(svg.save(dir / "no" / "f.svg"), Error);
}

TEST(Svg, RejectsBadViewsAndCoordinates) {
  EXPECT_THROW(SvgWriter{AABB2d{}}, Error);
  EXPECT_THROW(SvgWriter(AABB2d(Vec2d(0, 0), Vec2d(1, 1)), 10, 10), Error);
  SvgWriter flat(AABB2d(Vec2d(0, 0), Vec2d(4, 0)), 100, 0);  // a degenerate view still works
  EXPECT_DOUBLE_EQ(flat.height(), 0);
  SvgWriter svg(AABB2d(Vec2d(0, 0), Vec2d(1, 1)));
  EXPECT_THROW(svg.point(Vec2d(std::nan(""), 0)), Error);
  EXPECT_THROW(svg.circle(Vec2d(0, 0), -1), Error);
}

}  // namespace
}  // namespace geods::io
