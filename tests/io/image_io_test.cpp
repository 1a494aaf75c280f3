#include "geods/io/image_io.hpp"

#include <zlib.h>

#include <cmath>

#include "io_test_util.hpp"

namespace geods::io {
namespace {

using test::expect_error;
using test::TempDir;

Image<std::uint8_t> pattern(std::size_t w, std::size_t h, std::size_t c) {
  Image<std::uint8_t> im(w, h, c);
  for (std::size_t i = 0; i < im.size(); ++i) im.data[i] = std::uint8_t(i * 31 % 251);
  return im;
}

// A PNG written by hand, so 16-bit files are tested without a second encoder.
std::vector<std::uint8_t> png(std::uint32_t w, std::uint32_t h, int depth, int color, const std::vector<std::uint8_t>& rows) {
  std::vector<std::uint8_t> out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  auto be32 = [&](std::vector<std::uint8_t>& v, std::uint32_t x) {
    for (int s = 24; s >= 0; s -= 8) v.push_back(std::uint8_t(x >> s));
  };
  auto chunk = [&](const char* type, const std::vector<std::uint8_t>& body) {
    be32(out, std::uint32_t(body.size()));
    std::vector<std::uint8_t> tb(type, type + 4);
    tb.insert(tb.end(), body.begin(), body.end());
    out.insert(out.end(), tb.begin(), tb.end());
    be32(out, std::uint32_t(crc32(0, tb.data(), uInt(tb.size()))));
  };
  std::vector<std::uint8_t> ihdr;
  be32(ihdr, w);
  be32(ihdr, h);
  ihdr.insert(ihdr.end(), {std::uint8_t(depth), std::uint8_t(color), 0, 0, 0});
  chunk("IHDR", ihdr);
  uLongf n = compressBound(uLong(rows.size()));
  std::vector<std::uint8_t> z(n);
  compress(z.data(), &n, rows.data(), uLong(rows.size()));
  z.resize(n);
  chunk("IDAT", z);
  chunk("IEND", {});
  return out;
}

TEST(ImageIo, PngRoundTripEveryChannelCount) {
  TempDir dir;
  for (std::size_t c = 1; c <= 4; ++c) {
    const auto im = pattern(7, 5, c);
    write_png(dir / "p.png", im);
    const auto r = read_image(dir / "p.png");
    EXPECT_EQ(r.width, 7u);
    EXPECT_EQ(r.height, 5u);
    EXPECT_EQ(r.channels, c);
    EXPECT_EQ(r.data, im.data);
    const auto r16 = read_image16(dir / "p.png");  // 8-bit samples scaled to 16 bits
    ASSERT_EQ(r16.size(), im.size());
    for (std::size_t i = 0; i < im.size(); ++i) EXPECT_EQ(r16.data[i], im.data[i] * 257);
  }
}

TEST(ImageIo, SixteenBitPngRoundTripEveryChannelCount) {
  TempDir dir;
  for (std::size_t c = 1; c <= 4; ++c) {
    Image<std::uint16_t> im(9, 4, c);
    // Every byte value in both halves of the samples, and the extremes.
    for (std::size_t i = 0; i < im.size(); ++i) im.data[i] = std::uint16_t(i * 40503u % 65536u);
    im.data[0] = 0;
    im.data[1] = 65535;
    write_png(dir / "p16.png", im);
    EXPECT_EQ(image_bit_depth(dir / "p16.png"), 16);
    const auto r = read_image16(dir / "p16.png");
    EXPECT_EQ(r.width, 9u);
    EXPECT_EQ(r.height, 4u);
    EXPECT_EQ(r.channels, c);
    EXPECT_EQ(r.data, im.data);
  }
}

TEST(ImageIo, FloatPngScalesTheUnitIntervalAndRefusesTheRest) {
  TempDir dir;
  Image<float> im(5, 3, 2);
  for (std::size_t i = 0; i < im.size(); ++i) im.data[i] = float(i) / float(im.size() - 1);
  write_png(dir / "f.png", im);
  const auto r = read_image(dir / "f.png");
  ASSERT_EQ(r.size(), im.size());
  for (std::size_t i = 0; i < im.size(); ++i) EXPECT_EQ(r.data[i], std::lround(double(im.data[i]) * 255.0)) << i;
  EXPECT_EQ(r.data.back(), 255);  // 1.0 is white, not black
  Image<double> d(2, 1, 1);
  d.data = {0.5, 1.0};
  write_png(dir / "d.png", d);
  EXPECT_EQ(read_image(dir / "d.png").data, (std::vector<std::uint8_t>{128, 255}));
  for (const double bad : {1.0000001, -1e-300, std::nan(""), 255.0, 1e300}) {
    d.data = {0.25, bad};
    expect_error(dir / "bad.png", [&] { write_png(dir / "bad.png", d); }, "outside [0, 1]");
    EXPECT_FALSE(std::filesystem::exists(dir / "bad.png"));
  }
  expect_error(dir / "bad.png", [&] { write_png(dir / "bad.png", Image<float>(2, 2, 5)); }, "channels");
}

TEST(ImageIo, ReadsSixteenBitPngAndRealFile) {
  TempDir dir;
  // 2x1 grey, 16-bit: filter byte 0, then big-endian samples 0x1234 and 0xfedc.
  test::write_bytes(dir / "g16.png", png(2, 1, 16, 0, {0, 0x12, 0x34, 0xfe, 0xdc}));
  const auto im = read_image16(dir / "g16.png");
  EXPECT_EQ(im.data, (std::vector<std::uint16_t>{0x1234, 0xfedc}));
  EXPECT_EQ(read_image(dir / "g16.png").data, (std::vector<std::uint8_t>{0x12, 0xfe}));

  const auto brick = read_image(test::data_path("brick.png"));
  EXPECT_EQ(brick.width, 512u);
  EXPECT_EQ(brick.height, 512u);
  EXPECT_EQ(brick.channels, 1u);
}

TEST(ImageIo, ReadsBmp) {
  TempDir dir;
  // 2x1 24-bit bottom-up BMP: pixels stored BGR, rows padded to 4 bytes.
  std::vector<std::uint8_t> b = {'B', 'M', 62, 0, 0, 0, 0, 0, 0, 0, 54, 0, 0, 0, 40, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0,
                                 1, 0, 24, 0, 0, 0, 0, 0, 8, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
                                 3, 2, 1, 6, 5, 4, 0, 0};
  test::write_bytes(dir / "x.bmp", b);
  const auto im = read_image(dir / "x.bmp");
  EXPECT_EQ(im.width, 2u);
  EXPECT_EQ(im.channels, 3u);
  EXPECT_EQ(im.data, (std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6}));
}

TEST(ImageIo, MalformedFilesThrowNamingTheFile) {
  TempDir dir;
  expect_error(dir / "missing.png", [&] { read_image(dir / "missing.png"); }, "no such file");
  test::write_text(dir / "e.png", "");
  expect_error(dir / "e.png", [&] { read_image(dir / "e.png"); }, "empty");
  test::write_text(dir / "w.png", "GIF89a not a png");
  expect_error(dir / "w.png", [&] { read_image(dir / "w.png"); });
  // A 100-byte PNG claiming 16000 x 16000 pixels is rejected before decoding.
  test::write_bytes(dir / "huge.png", png(16000, 16000, 8, 0, {0, 1, 2, 3}));
  expect_error(dir / "huge.png", [&] { read_image(dir / "huge.png"); }, "header claims");
  write_png(dir / "ok.png", pattern(16, 16, 3));
  // stb checks neither CRCs nor the zlib checksum, and the IEND chunk carries
  // no pixels: cuts in the last 20 bytes lose nothing. Any earlier cut must fail.
  auto png_bytes = test::read_bytes(dir / "ok.png");
  png_bytes.resize(png_bytes.size() - 20);
  test::expect_truncations_fail(dir.path(), "cut.png", png_bytes, [](const std::filesystem::path& f) { read_image(f); });
  Image<std::uint8_t> bad(2, 2, 5);
  expect_error(dir / "bad.png", [&] { write_png(dir / "bad.png", bad); }, "channels");
}

}  // namespace
}  // namespace geods::io
