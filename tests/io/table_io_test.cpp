#include "geods/io/table_io.hpp"

#include <cmath>
#include <cstdint>
#include <random>
#include <sstream>

#include "geods/io/image_io.hpp"
#include "geods/io/npy.hpp"
#include "geods/io/output.hpp"
#include "geods/io/point_io.hpp"
#include "geods/io/svg.hpp"
#include "io_test_util.hpp"

namespace geods::io {
namespace {

using test::expect_error;
using test::TempDir;

TEST(TableIo, AnyColumnCountInEveryTextForm) {
  TempDir dir;
  // The oracle: the numbers as written; 5 columns, comments and blank lines in between.
  std::mt19937 rng(7);
  std::vector<double> values;
  std::string xyz = "# five columns\n", csv = "a,b,c,d,e\n", txt = "a b c d e\n";
  for (int r = 0; r < 20; ++r) {
    for (int c = 0; c < 5; ++c) {
      const double v = double(int(rng() % 2001) - 1000) / 8;
      values.push_back(v);
      std::ostringstream text;  // k/8 has at most 6 significant digits: printed exactly
      text << v;
      const std::string s = text.str();
      xyz += (c ? " " : "") + s;
      csv += (c ? "," : "") + s;
      txt += (c ? (c % 2 ? ", " : " ") : "") + s;  // blanks and commas mixed
    }
    xyz += "\n\n";
    csv += "\n";
    txt += "\r\n";
  }
  test::write_text(dir / "t.xyz", xyz);
  test::write_text(dir / "t.csv", csv);
  test::write_text(dir / "t.txt", txt);
  for (const char* name : {"t.xyz", "t.csv", "t.txt"}) {
    SCOPED_TRACE(name);
    const Table t = read_table(dir / name);
    EXPECT_EQ(t.rows, 20u);
    EXPECT_EQ(t.cols, 5u);
    EXPECT_EQ(t.dtype, DType::f64);
    EXPECT_EQ(t.values, values);
    EXPECT_EQ(t.row(3)[4], values[19]);
  }
}

TEST(TableIo, NpyKeepsItsDtypeAndAnyWidth) {
  TempDir dir;
  const std::vector<std::int32_t> ids = {0, 1, 2, 3, 4, 5, 6, 7};
  write_npy<std::int32_t>(dir / "i.npy", ids, {2, 4});
  const Table t = read_table(dir / "i.npy");
  EXPECT_TRUE(t.integer());
  EXPECT_EQ(t.dtype, DType::i32);
  EXPECT_EQ((std::vector<double>(t.values)), (std::vector<double>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(t.cols, 4u);
  // One column and seven columns are tables too.
  write_npy<float>(dir / "one.npy", std::vector<float>{1.5f, 2.5f}, {2, 1});
  EXPECT_EQ(read_table(dir / "one.npy").values, (std::vector<double>{1.5, 2.5}));
  EXPECT_FALSE(read_table(dir / "one.npy").integer());
  // A segment file of 4 columns reads as segments and as a table alike.
  write_npy<double>(dir / "s.npy", std::vector<double>{0, 0, 1, 1, 2, 2, 3, 3}, {2, 4});
  const SegmentMatrix s = read_segments(dir / "s.npy");
  EXPECT_EQ(std::vector<double>(s.data(), s.data() + s.size()), read_table(dir / "s.npy").values);
  test::write_text(dir / "s.csv", "x0,y0,x1,y1\n0,0,1,1\n2,2,3,3\n");
  EXPECT_EQ(read_segments(dir / "s.csv"), s);
}

TEST(TableIo, PointsAreTheFirstColumnsOfTheTable) {
  TempDir dir;
  test::write_text(dir / "p.txt", "x y z nx ny nz\n1,2,3,0,0,1\n4 5 6 0 1 0\n");
  const Table t = read_table(dir / "p.txt");
  EXPECT_EQ(t.cols, 6u);
  EXPECT_EQ(read_points(dir / "p.txt"), (PointMatrix(2, 3) << 1, 2, 3, 4, 5, 6).finished());
}

// A header is a first row none of whose fields is a number; any other first row is data.
TEST(TableIo, HeaderOnlyWhenNoFieldIsANumber) {
  TempDir dir;
  test::write_text(dir / "h.csv", "x,y\n1,2\n3,4\n");
  EXPECT_EQ(read_table(dir / "h.csv").rows, 2u);
  test::write_text(dir / "h.txt", "x y z\n1 2 3\n");
  EXPECT_EQ(read_table(dir / "h.txt").rows, 1u);
  // "0x10,2" is a row of data with a number geods does not read: an error naming it, not a dropped row.
  test::write_text(dir / "hex.csv", "0x10,2\n3,4\n");
  expect_error(dir / "hex.csv", [&] { read_table(dir / "hex.csv"); }, "'0x10' is not a number");
  test::write_text(dir / "mixed.csv", "x,2\n3,4\n");
  expect_error(dir / "mixed.csv", [&] { read_table(dir / "mixed.csv"); }, "'x' is not a number");
  test::write_text(dir / "nan.csv", "nan,2\n3,4\n");
  expect_error(dir / "nan.csv", [&] { read_table(dir / "nan.csv"); }, "non-finite");
  test::write_text(dir / "hex.txt", "0x1p3 5\n");
  expect_error(dir / "hex.txt", [&] { read_table(dir / "hex.txt"); }, "not a number");
}

// write_table: every accepted format reads back to the same values (the oracle: read_table and the input).
TEST(TableIo, WriteTableRoundTripsAndRefusesOtherNames) {
  TempDir dir;
  const std::vector<double> d = {0.1, -2.5e-300, 1e300, 3, 1.0 / 3.0, -0.0};
  const std::vector<std::int64_t> i = {-1, 0, 9007199254740993LL, 4};
  for (const char* name : {"t.npy", "t.csv", "t.txt"}) {
    write_table(dir / name, std::span<const double>(d), {3, 2});
    const Table t = read_table(dir / name);
    EXPECT_EQ(t.rows, 3u);
    EXPECT_EQ(t.cols, 2u);
    EXPECT_EQ(t.values, d) << name;
    write_table(dir / name, std::span<const std::int64_t>(i), {2, 2});
    const Table u = read_table(dir / name);
    EXPECT_EQ(u.rows, 2u);
    EXPECT_EQ(u.cols, 2u);
    EXPECT_EQ(u.values[0], -1.0);
    write_table(dir / name, std::span<const std::int64_t>(i), {4});  // 1-D: one value per line
  }
  // Integers are written as integers in text, not rounded through double.
  EXPECT_EQ(test::read_text(dir / "t.csv"), "-1\n0\n9007199254740993\n4\n");
  EXPECT_EQ(read_npy(dir / "t.npy").to_vector<std::int64_t>(), i);
  for (const char* name : {"t.ply", "t.jpg", "t.xyz", "t.png", "t", "t.npz"}) {
    expect_error(dir / name, [&] { write_table(dir / name, std::span<const double>(d), {6}); }, "accepted: .npy, .csv, .txt");
    EXPECT_FALSE(std::filesystem::exists(dir / name));
  }
  expect_error(dir / "s.npy", [&] { write_table(dir / "s.npy", std::span<const double>(d), {2, 2}); }, "shape");
  expect_error(dir / "s.npy", [&] { write_table(dir / "s.npy", std::span<const double>(d), {1, 2, 3}); }, "dimensions");
  // write_npy writes .npy files only.
  expect_error(dir / "n.csv", [&] { write_npy<double>(dir / "n.csv", d, {6}); }, "cannot write an array as '.csv' (accepted: .npy;");
  EXPECT_FALSE(std::filesystem::exists(dir / "n.csv"));
}

TEST(TableIo, OutputExtensionsPerKind) {
  check_output_extension("a.npy", OutputKind::table);
  check_output_extension("a.CSV", OutputKind::table);
  check_output_extension("-", OutputKind::table);
  check_output_extension("-", OutputKind::json);
  check_output_extension("a.ply", OutputKind::mesh);
  check_output_extension("a.png", OutputKind::image);
  expect_error("a.jpg", [] { check_output_extension("a.jpg", OutputKind::image); }, "accepted: .png)");
  expect_error("a.csv", [] { check_output_extension("a.csv", OutputKind::array); }, "accepted: .npy;");
  expect_error("a.off", [] { check_output_extension("a.off", OutputKind::mesh); }, "accepted: .ply, .obj, .stl)");
  expect_error("a.png", [] { check_output_extension("a.png", OutputKind::svg); }, ".svg");
  expect_error("-", [] { check_output_extension("-", OutputKind::mesh); }, "standard output");
  expect_error("-", [] { check_output_extension("-", OutputKind::image); }, "standard output");
  TempDir dir;
  expect_error(dir / "x.jpg", [&] { write_png(dir / "x.jpg", Image<std::uint8_t>(2, 2, 1)); }, "accepted: .png");
  expect_error(dir / "x.png", [&] { SvgWriter(AABB2d({0, 0}, {1, 1})).save(dir / "x.png"); }, "accepted: .svg");
  EXPECT_FALSE(std::filesystem::exists(dir / "x.jpg"));
  EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
}

TEST(TableIo, BadTablesThrowNamingTheFileAndLine) {
  TempDir dir;
  test::write_text(dir / "ragged.csv", "1,2,3\n4,5,6\n7,8\n");
  expect_error(dir / "ragged.csv", [&] { read_table(dir / "ragged.csv"); }, "line 3");
  test::write_text(dir / "word.txt", "1 2\n3 y\n");
  expect_error(dir / "word.txt", [&] { read_table(dir / "word.txt"); }, "line 2");
  test::write_text(dir / "nan.xyz", "1 2\nnan 3\n");
  expect_error(dir / "nan.xyz", [&] { read_table(dir / "nan.xyz"); }, "non-finite");
  test::write_text(dir / "header.xyz", "x y\n1 2\n");  // .xyz has no header line
  expect_error(dir / "header.xyz", [&] { read_table(dir / "header.xyz"); }, "not a number");
  test::write_text(dir / "empty.csv", "x,y\n");
  expect_error(dir / "empty.csv", [&] { read_table(dir / "empty.csv", "point"); }, "no points");
  write_npy<double>(dir / "inf.npy", std::vector<double>{1, 2, 3, INFINITY}, {2, 2});
  expect_error(dir / "inf.npy", [&] { read_table(dir / "inf.npy", "query point"); }, "query point 1 has a non-finite");
  write_npy<double>(dir / "cube.npy", std::vector<double>(8), {2, 2, 2});
  expect_error(dir / "cube.npy", [&] { read_table(dir / "cube.npy"); }, "2-D");
  test::write_text(dir / "w.csv", "1,2,3\n");
  expect_error(dir / "w.csv", [&] { read_table(dir / "w.csv", "box", 4); }, "n x 4");
  expect_error(dir / "t.obj", [&] { read_table(dir / "t.obj"); }, "unsupported");
  expect_error(dir / "missing.npy", [&] { read_table(dir / "missing.npy"); }, "no such file");
}

}  // namespace
}  // namespace geods::io
