#include "geods/io/volume_io.hpp"

#include <zlib.h>

#include "geods/io/npy.hpp"
#include "io_test_util.hpp"

namespace geods::io {
namespace {

using test::expect_error;
using test::TempDir;

template <typename T>
Grid3<T> ramp(std::size_t nx, std::size_t ny, std::size_t nz) {
  Grid3<T> g(nx, ny, nz);
  for (std::size_t i = 0; i < g.size(); ++i) g.data[i] = T(i % 120) - T(i % 3 == 0 ? 0 : 0);
  g.origin = {1.5f, -2.0f, 3.25f};
  g.spacing = {0.5f, 2.0f, 3.0f};
  return g;
}

template <typename T>
void expect_same(const AnyGrid3& read, const Grid3<T>& g, bool geometry) {
  ASSERT_TRUE(std::holds_alternative<Grid3<T>>(read));
  const auto& r = std::get<Grid3<T>>(read);
  EXPECT_EQ(r.dims, g.dims);
  EXPECT_EQ(r.data, g.data);
  if (geometry) {
    EXPECT_EQ(r.origin, g.origin);
    EXPECT_EQ(r.spacing, g.spacing);
  }
}

template <typename T>
void round_trip_all_formats(const TempDir& dir) {
  const Grid3<T> g = ramp<T>(5, 4, 3);
  const std::string tag(dtype_name(geods::dtype_of<T>()));
  for (const char* ext : {".npy", ".nrrd", ".nii", ".nii.gz"}) {
    SCOPED_TRACE(tag + ext);
    const auto p = dir / ("v_" + tag + ext);
    write_volume(p, g);
    expect_same(read_volume(p), g, std::string(ext) != ".npy");  // .npy has no geometry
  }
  // Raw: the samples only, x fastest, little-endian.
  const auto raw = dir / ("v_" + tag + ".raw");
  test::write_bytes(raw, std::vector<std::uint8_t>((const std::uint8_t*)g.data.data(),
                                                   (const std::uint8_t*)(g.data.data() + g.data.size())));
  expect_same(read_raw_volume(raw, {5, 4, 3}, geods::dtype_of<T>()), g, false);
}

TEST(VolumeIo, RoundTripEveryTypeAndFormat) {
  TempDir dir;
  round_trip_all_formats<std::uint8_t>(dir);
  round_trip_all_formats<std::uint16_t>(dir);
  round_trip_all_formats<std::int16_t>(dir);
  round_trip_all_formats<float>(dir);
  round_trip_all_formats<double>(dir);
}

TEST(VolumeIo, ReadsRealNifti) {
  const AnyGrid3 v = read_volume(test::data_path("t1_head.nii.gz"));
  const auto dims = std::visit([](const auto& g) { return g.dims; }, v);
  EXPECT_EQ(dims, (std::array<std::size_t, 3>{128, 128, 62}));
  const Grid3<float> f = to_float(v);
  EXPECT_FLOAT_EQ(f.spacing.x(), 2.0f);
  EXPECT_FLOAT_EQ(f.spacing.y(), 2.0f);
  EXPECT_FLOAT_EQ(f.spacing.z(), 3.0f);
  EXPECT_GT(*std::max_element(f.data.begin(), f.data.end()), 0.0f);
}

TEST(VolumeIo, NpyWidensTypesWithoutAGrid) {
  TempDir dir;
  const std::vector<std::int8_t> a = {-3, 4};
  write_npy<std::int8_t>(dir / "i8.npy", a, {1, 1, 2});
  expect_same(read_volume(dir / "i8.npy"), [] { Grid3<std::int16_t> g(2, 1, 1); g.data = {-3, 4}; return g; }(), false);
  const std::vector<std::int32_t> b = {-70000, 5};
  write_npy<std::int32_t>(dir / "i32.npy", b, {2, 1, 1});
  expect_same(read_volume(dir / "i32.npy"), [] { Grid3<double> g(1, 1, 2); g.data = {-70000, 5}; return g; }(), false);
  const std::vector<std::uint64_t> c = {1ull << 60};
  write_npy<std::uint64_t>(dir / "u64.npy", c, {1, 1, 1});
  expect_error(dir / "u64.npy", [&] { read_volume(dir / "u64.npy"); }, "exactly");
  const std::vector<float> d = {1, 2};
  write_npy<float>(dir / "2d.npy", d, {1, 2});
  expect_error(dir / "2d.npy", [&] { read_volume(dir / "2d.npy"); }, "3-D");
}

std::vector<std::uint8_t> gz(const std::vector<std::uint8_t>& raw) {
  uLongf n = compressBound(uLong(raw.size())) + 32;
  std::vector<std::uint8_t> out(n);
  z_stream zs{};
  deflateInit2(&zs, 6, Z_DEFLATED, 31, 8, Z_DEFAULT_STRATEGY);
  zs.next_in = const_cast<Bytef*>(raw.data());
  zs.avail_in = uInt(raw.size());
  zs.next_out = out.data();
  zs.avail_out = uInt(out.size());
  deflate(&zs, Z_FINISH);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  return out;
}

std::vector<std::uint8_t> cat(const std::string& header, const std::vector<std::uint8_t>& data) {
  std::vector<std::uint8_t> out(header.begin(), header.end());
  out.insert(out.end(), data.begin(), data.end());
  return out;
}

TEST(VolumeIo, NrrdVariants) {
  TempDir dir;
  // Big-endian shorts, gzip, type synonym, spacings, comments and key/values.
  const std::vector<std::uint8_t> be = {0, 1, 0xff, 0xfe, 1, 0, 0, 2};
  test::write_bytes(dir / "be.nrrd", cat("NRRD0005\n# comment\ntype: signed short int\ndimension: 3\nsizes: 2 2 1\n"
                                         "endian: big\nencoding: gzip\nspacings: 0.5 0.25 nan\nkey:=value\n\n", gz(be)));
  auto v = read_volume(dir / "be.nrrd");
  ASSERT_TRUE(std::holds_alternative<Grid3<std::int16_t>>(v));
  const auto& g = std::get<Grid3<std::int16_t>>(v);
  EXPECT_EQ(g.data, (std::vector<std::int16_t>{1, -2, 256, 2}));
  EXPECT_EQ(g.spacing, Vec3f(0.5f, 0.25f, 1.0f));
  // Detached header naming its data file, with space directions and origin.
  test::write_bytes(dir / "d.raw", {1, 2, 3, 4, 5, 6});
  test::write_text(dir / "d.nhdr", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 3 2 1\nencoding: raw\n"
                                   "space dimension: 3\nspace directions: (0,2,0) (0,0,3) (4,0,0)\n"
                                   "space origin: (7,8,9)\ndata file: d.raw\n");
  v = read_volume(dir / "d.nhdr");
  const auto& d = std::get<Grid3<std::uint8_t>>(v);
  EXPECT_EQ(d.data, (std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(d.spacing, Vec3f(2, 3, 4));
  EXPECT_EQ(d.origin, Vec3f(7, 8, 9));
}

TEST(VolumeIo, MalformedFilesThrowNamingTheFile) {
  TempDir dir;
  for (const char* name : {"missing.npy", "missing.nrrd", "missing.nii", "missing.nii.gz"})
    expect_error(dir / name, [&] { read_volume(dir / name); }, "no such file");
  for (const char* name : {"e.npy", "e.nrrd", "e.nii", "e.nii.gz"}) {
    test::write_text(dir / name, "");
    expect_error(dir / name, [&] { read_volume(dir / name); });
  }
  expect_error(dir / "v.vtk", [&] { read_volume(dir / "v.vtk"); }, "unsupported");
  test::write_text(dir / "w.nrrd", "NRRX0004\n");
  expect_error(dir / "w.nrrd", [&] { read_volume(dir / "w.nrrd"); }, "magic");
  test::write_text(dir / "w.nii", std::string(400, 'x'));
  expect_error(dir / "w.nii", [&] { read_volume(dir / "w.nii"); });

  // Absurd sizes: rejected before allocating.
  test::write_text(dir / "big.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 100000 100000 100000\nendian: little\n"
                                     "encoding: raw\n\n1234");
  expect_error(dir / "big.nrrd", [&] { read_volume(dir / "big.nrrd"); }, "truncated");
  test::write_text(dir / "ovf.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 18446744073709551615 2 2\n"
                                     "endian: little\nencoding: raw\n\n1234");
  expect_error(dir / "ovf.nrrd", [&] { read_volume(dir / "ovf.nrrd"); }, "overflow");
  test::write_bytes(dir / "bomb.nrrd", cat("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: gzip\n\n",
                                           gz(std::vector<std::uint8_t>(1 << 20))));
  expect_error(dir / "bomb.nrrd", [&] { read_volume(dir / "bomb.nrrd"); }, "expands");
  test::write_text(dir / "enc.nrrd", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: bzip2\n\nx");
  expect_error(dir / "enc.nrrd", [&] { read_volume(dir / "enc.nrrd"); }, "encoding");
  test::write_text(dir / "typ.nrrd", "NRRD0004\ntype: block\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\nx");
  expect_error(dir / "typ.nrrd", [&] { read_volume(dir / "typ.nrrd"); }, "type");
  test::write_text(dir / "dim.nrrd", "NRRD0004\ntype: uchar\ndimension: 2\nsizes: 1 1\nencoding: raw\n\nx");
  expect_error(dir / "dim.nrrd", [&] { read_volume(dir / "dim.nrrd"); }, "3-D");
  test::write_text(dir / "nodata.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\ndata file: nope.raw\n");
  expect_error(dir / "nope.raw", [&] { read_volume(dir / "nodata.nhdr"); }, "no such file");
  test::write_text(dir / "dev.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\ndata file: /dev/zero\n");
  expect_error(dir / "dev.nhdr", [&] { read_volume(dir / "dev.nhdr"); }, "regular");

  // NIfTI: a header claiming 32767^3 samples, 4-D data, complex data, two-file magic.
  Grid3<std::uint8_t> small(4, 3, 2, 7);
  write_volume(dir / "ok.nii", small);
  auto nii = test::read_bytes(dir / "ok.nii");
  auto patched = [&](std::size_t offset, std::vector<std::uint8_t> bytes) {
    auto b = nii;
    std::copy(bytes.begin(), bytes.end(), b.begin() + std::ptrdiff_t(offset));
    return b;
  };
  test::write_bytes(dir / "huge.nii", patched(42, {0xff, 0x7f, 0xff, 0x7f, 0xff, 0x7f}));
  expect_error(dir / "huge.nii", [&] { read_volume(dir / "huge.nii"); }, "truncated");
  test::write_bytes(dir / "huge.nii.gz", gz(patched(42, {0xff, 0x7f, 0xff, 0x7f, 0xff, 0x7f})));
  expect_error(dir / "huge.nii.gz", [&] { read_volume(dir / "huge.nii.gz"); }, "truncated");
  test::write_bytes(dir / "4d.nii", patched(40, {4, 0, 4, 0, 3, 0, 2, 0, 2, 0}));
  expect_error(dir / "4d.nii", [&] { read_volume(dir / "4d.nii"); }, "3-D");
  test::write_bytes(dir / "cplx.nii", patched(70, {32, 0, 64, 0}));
  expect_error(dir / "cplx.nii", [&] { read_volume(dir / "cplx.nii"); }, "datatype");
  test::write_bytes(dir / "pair.nii", patched(344, {'n', 'i', '1', 0}));
  expect_error(dir / "pair.nii", [&] { read_volume(dir / "pair.nii"); }, ".hdr");
  test::write_bytes(dir / "neg.nii", patched(42, {0xff, 0xff}));
  expect_error(dir / "neg.nii", [&] { read_volume(dir / "neg.nii"); });

  auto read = [](const std::filesystem::path& f) { read_volume(f); };
  test::expect_truncations_fail(dir.path(), "cut.nii", nii, read);
  test::expect_truncations_fail(dir.path(), "cut.nii.gz", gz(nii), read);
  write_volume(dir / "ok.nrrd", small);
  test::expect_truncations_fail(dir.path(), "cut.nrrd", test::read_bytes(dir / "ok.nrrd"), read);
  write_volume(dir / "ok.npy", small);
  test::expect_truncations_fail(dir.path(), "cut.npy", test::read_bytes(dir / "ok.npy"), read);

  // Raw: the size must match exactly.
  test::write_bytes(dir / "r.raw", std::vector<std::uint8_t>(23));
  expect_error(dir / "r.raw", [&] { read_raw_volume(dir / "r.raw", {2, 3, 2}, DType::u16); }, "24");
  expect_error(dir / "r.raw", [&] { read_raw_volume(dir / "r.raw", {1ull << 40, 1ull << 40, 1ull << 40}, DType::f64); }, "overflow");
}

TEST(VolumeIo, NiftiScalingConvertsToFloat) {
  TempDir dir;
  Grid3<std::int16_t> g(2, 1, 1);
  g.data = {10, -4};
  write_volume(dir / "s.nii", g);
  auto b = test::read_bytes(dir / "s.nii");
  const float slope = 0.5f, inter = 100.0f;
  std::memcpy(b.data() + 112, &slope, 4);
  std::memcpy(b.data() + 116, &inter, 4);
  test::write_bytes(dir / "s.nii", b);
  const AnyGrid3 v = read_volume(dir / "s.nii");
  ASSERT_TRUE(std::holds_alternative<Grid3<float>>(v));
  EXPECT_EQ(std::get<Grid3<float>>(v).data, (std::vector<float>{105.0f, 98.0f}));
}

}  // namespace
}  // namespace geods::io
