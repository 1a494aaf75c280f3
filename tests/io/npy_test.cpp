#include "geods/io/npy.hpp"

#include <cmath>
#include <limits>

#include "io_test_util.hpp"

namespace geods::io {
namespace {

using test::expect_error;
using test::TempDir;

// An npy file assembled by hand: version, header dict and raw data bytes.
std::vector<std::uint8_t> npy_bytes(const std::string& dict, const std::vector<std::uint8_t>& data, int major = 1) {
  std::vector<std::uint8_t> out = {0x93, 'N', 'U', 'M', 'P', 'Y', std::uint8_t(major), 0};
  std::string header = dict;
  const std::size_t pre = major == 1 ? 10 : 12;
  while ((pre + header.size() + 1) % 64) header += ' ';
  header += '\n';
  const std::size_t n = header.size();
  out.push_back(std::uint8_t(n & 0xff));
  out.push_back(std::uint8_t(n >> 8));
  if (major != 1) {
    out.push_back(0);
    out.push_back(0);
  }
  out.insert(out.end(), header.begin(), header.end());
  out.insert(out.end(), data.begin(), data.end());
  return out;
}

template <typename T>
void round_trip(const TempDir& dir) {
  std::vector<T> values;
  for (int i = 0; i < 12; ++i) values.push_back(T(i * 7 % 100));
  values[3] = std::numeric_limits<T>::max();
  values[4] = std::numeric_limits<T>::lowest();
  const auto p = dir / ("a_" + std::string(dtype_name(dtype_of<T>())) + ".npy");
  write_npy<T>(p, values, {3, 4});
  const NpyArray a = read_npy(p);
  EXPECT_EQ(a.dtype, dtype_of<T>());
  EXPECT_EQ(a.shape, (std::vector<std::size_t>{3, 4}));
  EXPECT_EQ(a.size(), 12u);
  EXPECT_EQ(a.to_vector<T>(), values);
}

TEST(Npy, RoundTripEveryDtype) {
  TempDir dir;
  round_trip<std::uint8_t>(dir);
  round_trip<std::int8_t>(dir);
  round_trip<std::uint16_t>(dir);
  round_trip<std::int16_t>(dir);
  round_trip<std::uint32_t>(dir);
  round_trip<std::int32_t>(dir);
  round_trip<std::uint64_t>(dir);
  round_trip<std::int64_t>(dir);
  round_trip<float>(dir);
  round_trip<double>(dir);
}

TEST(Npy, HeaderIsAlignedAndShapesOfAnyRank) {
  TempDir dir;
  const std::vector<double> v = {1.5};
  for (const auto& shape : {std::vector<std::size_t>{}, {1}, {1, 1, 1, 1}}) {
    write_npy<double>(dir / "s.npy", v, shape);
    const auto bytes = test::read_bytes(dir / "s.npy");
    EXPECT_EQ((bytes.size() - 8) % 64, 0u);
    const NpyArray a = read_npy(dir / "s.npy");
    EXPECT_EQ(a.shape, shape);
    EXPECT_EQ(a.to_vector<double>(), v);
  }
  write_npy<float>(dir / "e.npy", {}, {0, 3});
  EXPECT_EQ(read_npy(dir / "e.npy").size(), 0u);
}

TEST(Npy, ReadsBigEndianVersionsTwoThreeAndBool) {
  TempDir dir;
  test::write_bytes(dir / "be.npy", npy_bytes("{'descr': '>i4', 'fortran_order': False, 'shape': (2,), }",
                                              {0, 0, 1, 2, 0xff, 0xff, 0xff, 0xfe}));
  EXPECT_EQ(read_npy(dir / "be.npy").to_vector<std::int32_t>(), (std::vector<std::int32_t>{258, -2}));
  test::write_bytes(dir / "v2.npy", npy_bytes("{\"descr\": \"<u2\", \"fortran_order\": False, \"shape\": (1, 2)}",
                                              {1, 0, 2, 0}, 2));
  EXPECT_EQ(read_npy(dir / "v2.npy").to_vector<int>(), (std::vector<int>{1, 2}));
  test::write_bytes(dir / "v3.npy", npy_bytes("{'descr': '|b1', 'fortran_order': False, 'shape': (3,), }", {1, 0, 1}, 3));
  const NpyArray b = read_npy(dir / "v3.npy");
  EXPECT_EQ(b.dtype, DType::u8);
  EXPECT_EQ(b.to_vector<float>(), (std::vector<float>{1, 0, 1}));
  test::write_bytes(dir / "bef.npy", npy_bytes("{'descr': '>f8', 'fortran_order': False, 'shape': (1,), }",
                                               {0x3f, 0xf8, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(read_npy(dir / "bef.npy").to_vector<double>(), (std::vector<double>{1.5}));
}

// Fortran order: element (i0, i1, ...) is at offset i0 + d0 * (i1 + d1 * ...).
// The oracle builds the Fortran bytes from that formula; read_npy must give the C-order values.
TEST(Npy, ReadsFortranOrderAsCOrder) {
  TempDir dir;
  for (const std::vector<std::size_t>& shape : {std::vector<std::size_t>{3, 4}, {2, 3, 4}, {5, 1, 2}, {1, 6}, {7}, {2, 2, 2, 3}}) {
    std::size_t n = 1;
    for (std::size_t d : shape) n *= d;
    std::vector<std::int16_t> c_order(n), fortran(n);
    for (std::size_t i = 0; i < n; ++i) c_order[i] = std::int16_t(1000 - 7 * int(i));
    for (std::size_t i = 0; i < n; ++i) {
      std::size_t rest = i, offset = 0, stride = 1;  // C-order multi-index of i, from the last axis
      std::vector<std::size_t> index(shape.size());
      for (std::size_t j = shape.size(); j-- > 0;) index[j] = rest % shape[j], rest /= shape[j];
      for (std::size_t j = 0; j < shape.size(); ++j) offset += index[j] * stride, stride *= shape[j];
      fortran[offset] = c_order[i];
    }
    std::vector<std::uint8_t> bytes(n * 2);
    for (std::size_t i = 0; i < n; ++i) {  // big-endian too, so byte swapping and reordering meet
      bytes[2 * i] = std::uint8_t(std::uint16_t(fortran[i]) >> 8);
      bytes[2 * i + 1] = std::uint8_t(std::uint16_t(fortran[i]) & 0xff);
    }
    std::string dims;
    for (std::size_t d : shape) dims += std::to_string(d) + ",";
    test::write_bytes(dir / "f.npy", npy_bytes("{'descr': '>i2', 'fortran_order': True, 'shape': (" + dims + "), }", bytes));
    const NpyArray a = read_npy(dir / "f.npy");
    EXPECT_EQ(a.shape, shape);
    EXPECT_EQ(a.to_vector<std::int16_t>(), c_order);
  }
}

TEST(Npy, ReadsRealFile) {
  const NpyArray a = read_npy(test::data_path("jacksboro_dem.npy"));
  EXPECT_EQ(a.dtype, DType::i16);
  EXPECT_EQ(a.shape, (std::vector<std::size_t>{344, 403}));
  const auto v = a.to_vector<double>();
  EXPECT_GT(*std::max_element(v.begin(), v.end()), 0.0);
}

TEST(Npy, ConversionRefusesValuesThatDoNotFit) {
  TempDir dir;
  const std::vector<double> v = {1.0, std::nan("")};
  write_npy<double>(dir / "n.npy", v, {2});
  EXPECT_THROW(read_npy(dir / "n.npy").to_vector<int>(), Error);
  const std::vector<std::int32_t> w = {-1};
  write_npy<std::int32_t>(dir / "w.npy", w, {1});
  EXPECT_THROW(read_npy(dir / "w.npy").to_vector<std::uint32_t>(), Error);
  EXPECT_EQ(read_npy(dir / "w.npy").to_vector<std::int64_t>(), (std::vector<std::int64_t>{-1}));
}

TEST(Npy, MalformedFilesThrowNamingTheFile) {
  TempDir dir;
  const auto p = dir / "bad.npy";
  expect_error(dir / "missing.npy", [&] { read_npy(dir / "missing.npy"); }, "no such file");
  test::write_bytes(p, {});
  expect_error(p, [&] { read_npy(p); }, "empty");
  test::write_text(p, "PK\x03\x04 not numpy at all");
  expect_error(p, [&] { read_npy(p); }, "magic");
  // 10^12 elements promised by a 100-byte file: an error before any allocation.
  test::write_bytes(p, npy_bytes("{'descr': '<f8', 'fortran_order': False, 'shape': (1000000, 1000000), }", {}));
  expect_error(p, [&] { read_npy(p); }, "truncated");
  test::write_bytes(p, npy_bytes("{'descr': '<f8', 'fortran_order': False, 'shape': (4294967296, 4294967296, 4294967296), }", {}));
  expect_error(p, [&] { read_npy(p); }, "overflow");
  test::write_bytes(p, npy_bytes("{'descr': '<c16', 'fortran_order': False, 'shape': (1,), }", std::vector<std::uint8_t>(16)));
  expect_error(p, [&] { read_npy(p); }, "dtype");
  test::write_bytes(p, npy_bytes("{'descr': [('a', '<f8')], 'fortran_order': False, 'shape': (1,), }", std::vector<std::uint8_t>(8)));
  expect_error(p, [&] { read_npy(p); }, "structured");
  test::write_bytes(p, npy_bytes("{'descr': '<f8', 'fortran_order': False, 'shape': (-1,), }", {}));
  expect_error(p, [&] { read_npy(p); });
  test::write_bytes(p, npy_bytes("{'descr': '<f8', 'fortran_order': False, 'shape': (1,), }", std::vector<std::uint8_t>(9)));
  expect_error(p, [&] { read_npy(p); }, "unexpected bytes");
  test::write_bytes(p, npy_bytes("{'descr': '<f8', 'shape': (1,), }", std::vector<std::uint8_t>(8)));
  expect_error(p, [&] { read_npy(p); });
  test::write_bytes(p, npy_bytes("{'descr': '<f8', 'fortran_order': False, 'shape': (1,), }", std::vector<std::uint8_t>(8), 7));
  expect_error(p, [&] { read_npy(p); }, "version");

  std::vector<double> v(100, 2.0);
  write_npy<double>(dir / "good.npy", v, {10, 10});
  test::expect_truncations_fail(dir.path(), "cut.npy", test::read_bytes(dir / "good.npy"), [](const auto& f) { read_npy(f); });
}

}  // namespace
}  // namespace geods::io
