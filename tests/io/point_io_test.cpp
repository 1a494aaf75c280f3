#include "geods/io/point_io.hpp"

#include <cmath>
#include <limits>

#include "geods/io/npy.hpp"
#include "io_test_util.hpp"

namespace geods::io {
namespace {

using test::expect_error;
using test::TempDir;

PointMatrix sample(int dim) {
  PointMatrix p(4, dim);
  for (int i = 0; i < 4; ++i)
    for (int c = 0; c < dim; ++c) p(i, c) = 0.1 * i - 1e-7 * c + (c == 1 ? 1e10 : 0.0);
  return p;
}

TEST(PointIo, RoundTripEveryFormat) {
  TempDir dir;
  for (int dim : {2, 3})
    for (const char* ext : {".npy", ".xyz", ".csv", ".ply"}) {
      SCOPED_TRACE(std::string(ext) + " dim " + std::to_string(dim));
      const auto p = dir / (std::string("p") + ext);
      write_points(p, sample(dim));
      EXPECT_EQ(read_points(p), sample(dim));  // exact: shortest round-trip text
    }
}

TEST(PointIo, ReadsRealFilesAndVariants) {
  const PointMatrix land = read_points(test::data_path("land_points.npy"));
  EXPECT_EQ(land.rows(), 4996);
  EXPECT_EQ(land.cols(), 2);
  const SegmentMatrix seg = read_segments(test::data_path("land_segments.npy"));
  EXPECT_EQ(seg.rows(), 4999);

  TempDir dir;
  test::write_text(dir / "n.xyz", "# x y z nx ny nz\n1 2 3 0 0 1\n\n4 5 6 0 1 0\r\n");
  EXPECT_EQ(read_points(dir / "n.xyz"), (PointMatrix(2, 3) << 1, 2, 3, 4, 5, 6).finished());
  test::write_text(dir / "h.csv", "lon,lat\n1.5,-2\n+3,4e1\n");
  EXPECT_EQ(read_points(dir / "h.csv"), (PointMatrix(2, 2) << 1.5, -2, 3, 40).finished());
  const std::vector<float> f = {1, 2, 3, 4};
  write_npy<float>(dir / "f.npy", f, {2, 2});
  EXPECT_EQ(read_points(dir / "f.npy"), (PointMatrix(2, 2) << 1, 2, 3, 4).finished());
  // A binary PLY mesh: faces after the vertices are parsed and skipped.
  std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty double x\nproperty double y\n"
                    "property double z\nproperty uchar red\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const double xyz[6] = {1, 2, 3, 4, 5, 6};
  for (int v = 0; v < 2; ++v) {
    ply.append(reinterpret_cast<const char*>(xyz + 3 * v), 24);
    ply += '\x07';
  }
  ply += '\x03';
  ply.append(12, '\0');  // triangle 0 0 0
  test::write_text(dir / "m.ply", ply);
  EXPECT_EQ(read_points(dir / "m.ply"), (PointMatrix(2, 3) << 1, 2, 3, 4, 5, 6).finished());

  test::write_text(dir / "s.edg", "2\n0 0 1 1\n1 1 2 0\n");
  EXPECT_EQ(read_segments(dir / "s.edg"), (SegmentMatrix(2, 4) << 0, 0, 1, 1, 1, 1, 2, 0).finished());
  test::write_text(dir / "s.cin", "# sites\np 5 5\ns 0 0 1 1\np 6 6\ns 1 1 2 0\n");
  EXPECT_EQ(read_segments(dir / "s.cin"), (SegmentMatrix(2, 4) << 0, 0, 1, 1, 1, 1, 2, 0).finished());
}

TEST(PointIo, MalformedFilesThrowNamingTheFile) {
  TempDir dir;
  for (const char* name : {"m.npy", "m.xyz", "m.csv", "m.ply"})
    expect_error(dir / name, [&] { read_points(dir / name); }, "no such file");
  for (const char* name : {"m.edg", "m.cin"}) expect_error(dir / name, [&] { read_segments(dir / name); }, "no such file");
  for (const char* name : {"e.npy", "e.xyz", "e.csv", "e.ply"}) {
    test::write_text(dir / name, "");
    expect_error(dir / name, [&] { read_points(dir / name); });
  }
  for (const char* name : {"e.edg", "e.cin"}) {
    test::write_text(dir / name, "");
    expect_error(dir / name, [&] { read_segments(dir / name); });
  }
  test::write_text(dir / "c.xyz", "# only a comment\n\n");
  expect_error(dir / "c.xyz", [&] { read_points(dir / "c.xyz"); }, "no points");
  test::write_text(dir / "nan.xyz", "1 2 3\n4 nan 6\n");
  expect_error(dir / "nan.xyz", [&] { read_points(dir / "nan.xyz"); }, "line 2");
  test::write_text(dir / "inf.csv", "x,y\n1,inf\n");
  expect_error(dir / "inf.csv", [&] { read_points(dir / "inf.csv"); }, "non-finite");
  test::write_text(dir / "short.xyz", "1 2 3\n4 5\n");
  expect_error(dir / "short.xyz", [&] { read_points(dir / "short.xyz"); }, "line 2");
  test::write_text(dir / "word.csv", "1,2\n3,x\n");
  expect_error(dir / "word.csv", [&] { read_points(dir / "word.csv"); }, "not a number");
  const std::vector<double> nan = {1, std::nan("")};
  write_npy<double>(dir / "nan.npy", nan, {1, 2});
  expect_error(dir / "nan.npy", [&] { read_points(dir / "nan.npy"); }, "non-finite");
  write_npy<double>(dir / "shape.npy", nan, {2});
  expect_error(dir / "shape.npy", [&] { read_points(dir / "shape.npy"); }, "n x");
  write_npy<double>(dir / "none.npy", {}, {0, 3});
  expect_error(dir / "none.npy", [&] { read_points(dir / "none.npy"); }, "no points");
  test::write_text(dir / "big.ply", "ply\nformat ascii 1.0\nelement vertex 99999999999\nproperty float x\nproperty float y\nend_header\n1 2\n");
  expect_error(dir / "big.ply", [&] { read_points(dir / "big.ply"); }, "truncated");
  test::write_text(dir / "nan.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 nan\n");
  expect_error(dir / "nan.ply", [&] { read_points(dir / "nan.ply"); }, "non-finite");
  test::write_text(dir / "w.ply", "PLY\n");
  expect_error(dir / "w.ply", [&] { read_points(dir / "w.ply"); }, "magic");
  expect_error(dir / "p.txt2", [&] { read_points(dir / "p.txt2"); }, "unsupported");

  test::write_text(dir / "n.edg", "5\n0 0 1 1\n");
  expect_error(dir / "n.edg", [&] { read_segments(dir / "n.edg"); }, "truncated");
  test::write_text(dir / "x.edg", "1\n0 0 1 1\n2 2 3 3\n");
  expect_error(dir / "x.edg", [&] { read_segments(dir / "x.edg"); });
  test::write_text(dir / "big.edg", "100000000000000\n0 0 1 1\n");
  expect_error(dir / "big.edg", [&] { read_segments(dir / "big.edg"); }, "truncated");
  test::write_text(dir / "nan.cin", "s 0 0 nan 1\n");
  expect_error(dir / "nan.cin", [&] { read_segments(dir / "nan.cin"); }, "line 1");
  test::write_text(dir / "q.cin", "q 1 2\n");
  expect_error(dir / "q.cin", [&] { read_segments(dir / "q.cin"); }, "line 1");
  test::write_text(dir / "p.cin", "p 1 2\n");
  expect_error(dir / "p.cin", [&] { read_segments(dir / "p.cin"); }, "no segments");
  write_npy<double>(dir / "s3.npy", nan, {1, 2});
  expect_error(dir / "s3.npy", [&] { read_segments(dir / "s3.npy"); }, "n x 4");

  write_points(dir / "ok.ply", sample(3));
  auto ply = test::read_bytes(dir / "ok.ply");
  // A cut inside a number of an ascii file can leave a valid shorter number: lenient here...
  test::expect_truncations_fail(dir.path(), "cut.ply", ply, [](const std::filesystem::path& f) { read_points(f); }, false);
  // ...but a missing vertex is always found.
  std::string text(ply.begin(), ply.end());
  text.erase(text.rfind('\n', text.size() - 2) + 1);
  test::write_text(dir / "cut.ply", text);
  expect_error(dir / "cut.ply", [&] { read_points(dir / "cut.ply"); }, "truncated");
  write_points(dir / "ok.npy", sample(3));
  test::expect_truncations_fail(dir.path(), "cut.npy", test::read_bytes(dir / "ok.npy"),
                                [](const std::filesystem::path& f) { read_points(f); });
  PointMatrix four(1, 4);
  four.setZero();
  expect_error(dir / "four.xyz", [&] { write_points(dir / "four.xyz", four); }, "2 or 3");
  // Non-finite points are refused before anything is written (read_points would refuse the file).
  for (const char* name : {"out.npy", "out.xyz", "out.csv", "out.ply", "out.txt"}) {
    for (const double bad : {std::nan(""), std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()}) {
      PointMatrix p = sample(2);
      p(3, 1) = bad;
      expect_error(dir / name, [&] { write_points(dir / name, p); }, "point 3 has a non-finite coordinate");
      EXPECT_FALSE(std::filesystem::exists(dir / name));
    }
  }
}

}  // namespace
}  // namespace geods::io
