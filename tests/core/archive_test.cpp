// The archive container (ArchiveWriter / Archive) and FlatArray: round trips,
// in-place views, and every kind of bad file giving geods::Error.
#include "geods/core/archive.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numeric>
#include <string>
#include <vector>

namespace geods {
namespace {

namespace fs = std::filesystem;

struct Node {
  std::uint32_t begin, end;
  float low, high;
};

fs::path temp_file(const std::string& name) { return fs::temp_directory_path() / ("geods_archive_" + name); }

std::vector<char> read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void write_all(const fs::path& p, const std::vector<char>& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

fs::path write_sample(const std::string& name) {
  std::vector<float> points(3001);
  std::iota(points.begin(), points.end(), 0.5f);
  std::vector<Node> nodes = {{0, 10, 1.5f, 2.5f}, {10, 20, -1, 7}};
  std::vector<std::uint32_t> none;
  ArchiveWriter w("test.Sample", 3);
  w.add("points", points);
  w.add("nodes", nodes);
  w.add("empty", none);
  w.add_value("leaf_size", std::uint64_t(10));
  const fs::path p = temp_file(name);
  w.write(p);
  return p;
}

TEST(FlatArray, OwnsOrViewsAndCopiesKeepTheirOwnData) {
  FlatArray<int> a(std::vector<int>{1, 2, 3});
  EXPECT_FALSE(a.mapped());
  EXPECT_EQ(a.owned_bytes(), 3 * sizeof(int));
  FlatArray<int> b = a;
  EXPECT_NE(a.data(), b.data());
  EXPECT_EQ(b.to_vector(), (std::vector<int>{1, 2, 3}));
  const int* before = a.data();
  FlatArray<int> c = std::move(a);
  EXPECT_EQ(c.data(), before);  // moving keeps the buffer
  EXPECT_TRUE(a.empty());

  static const int backing[4] = {4, 5, 6, 7};
  FlatArray<int> v(std::span<const int>(backing), std::make_shared<int>(0));
  EXPECT_TRUE(v.mapped());
  EXPECT_EQ(v.owned_bytes(), 0u);
  FlatArray<int> w = v;
  EXPECT_EQ(w.data(), backing);
  EXPECT_EQ(w[3], 7);
}

TEST(FlatArray, TakeVectorMovesWhatItOwnsAndCopiesAView) {
  std::vector<int> elements = {1, 2, 3};
  const int* buffer = elements.data();
  FlatArray<int> a(std::move(elements));
  std::vector<int> taken = std::move(a).take_vector();
  EXPECT_EQ(taken.data(), buffer);  // moved out, not copied
  EXPECT_EQ(taken, (std::vector<int>{1, 2, 3}));
  EXPECT_TRUE(a.empty());  // NOLINT(bugprone-use-after-move): left empty on purpose

  static const int backing[3] = {4, 5, 6};
  FlatArray<int> v(std::span<const int>(backing), std::make_shared<int>(0));
  taken = std::move(v).take_vector();
  EXPECT_NE(taken.data(), backing);  // a copy the caller may change
  EXPECT_EQ(taken, (std::vector<int>{4, 5, 6}));
  EXPECT_TRUE(v.empty());  // NOLINT(bugprone-use-after-move)
  EXPECT_TRUE(std::move(FlatArray<int>()).take_vector().empty());
}

// An allocator other than std::allocator (as HugePageAllocator is).
template <typename T>
struct CountingAllocator {
  using value_type = T;
  CountingAllocator() = default;
  template <typename U>
  CountingAllocator(const CountingAllocator<U>&) {}
  T* allocate(std::size_t n) { return std::allocator<T>().allocate(n); }
  void deallocate(T* p, std::size_t n) { std::allocator<T>().deallocate(p, n); }
  bool operator==(const CountingAllocator&) const { return true; }
};

TEST(FlatArray, HoldsAVectorOfAnotherAllocatorAndCompares) {
  std::vector<int, CountingAllocator<int>> v = {5, 6, 7};
  const int* buffer = v.data();
  const FlatArray<int> a(std::move(v));
  EXPECT_EQ(a.data(), buffer);  // moved in, not copied
  EXPECT_FALSE(a.mapped());
  EXPECT_EQ(a.owned_bytes(), 3 * sizeof(int));
  const FlatArray<int> b = a;  // copies share the held vector
  EXPECT_EQ(b.data(), buffer);
  EXPECT_TRUE(a == FlatArray<int>(std::vector<int>{5, 6, 7}));
  EXPECT_FALSE(a == FlatArray<int>(std::vector<int>{5, 6}));
  EXPECT_FALSE(a == FlatArray<int>(std::vector<int>{5, 6, 8}));
}

TEST(Archive, RoundTripReadsSectionsInPlace) {
  const fs::path p = write_sample("round_trip");
  const Archive a = Archive::open(p, "test.Sample", 3);
  const FlatArray<float> points = a.array<float>("points", 3001);
  EXPECT_TRUE(points.mapped());
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(points.data()) % 64, 0u);
  for (std::size_t i = 0; i < points.size(); ++i) ASSERT_EQ(points[i], float(i) + 0.5f);
  const FlatArray<Node> nodes = a.array<Node>("nodes");
  ASSERT_EQ(nodes.size(), 2u);
  EXPECT_EQ(nodes[1].end, 20u);
  EXPECT_EQ(nodes[1].high, 7.0f);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(nodes.data()) % 64, 0u);
  EXPECT_TRUE(a.array<std::uint32_t>("empty").empty());
  EXPECT_EQ(a.value<std::uint64_t>("leaf_size"), 10u);
  EXPECT_TRUE(a.has("nodes"));
  EXPECT_FALSE(a.has("perm"));
  const Archive::Kind k = Archive::peek(p);
  EXPECT_EQ(k.kind, "test.Sample");
  EXPECT_EQ(k.version, 3u);
  fs::remove(p);
}

TEST(Archive, ViewsOutliveTheArchiveObject) {
  const fs::path p = write_sample("outlive");
  FlatArray<float> points;
  { points = Archive::open(p, "test.Sample", 3).array<float>("points"); }
  fs::remove(p);  // the mapping stays valid after the name is gone
  EXPECT_EQ(points[3000], 3000.5f);
}

TEST(Archive, WrongKindVersionTypeCountAndMissingSectionsAreErrors) {
  const fs::path p = write_sample("wrong");
  try {
    (void)Archive::open(p, "test.Other", 3);
    FAIL() << "a test.Sample archive opened as a test.Other";
  } catch (const Error& e) {  // one line naming the file, what it holds and what was expected
    EXPECT_EQ(std::string(e.what()), p.string() + ": holds a geods archive of kind test.Sample, expected kind test.Other");
  }
  EXPECT_THROW(Archive::open(p, "test.Sample", 4), Error);
  const Archive a = Archive::open(p, "test.Sample", 3);
  EXPECT_THROW(a.array<double>("points"), Error);
  EXPECT_THROW(a.array<std::int32_t>("empty"), Error);
  EXPECT_THROW(a.array<float>("points", 3000), Error);
  EXPECT_THROW(a.array<float>("nope"), Error);
  EXPECT_THROW(a.value<std::uint32_t>("leaf_size"), Error);
  fs::remove(p);
}

TEST(Archive, EveryTruncationIsAnError) {
  const fs::path p = write_sample("truncate");
  const std::vector<char> bytes = read_all(p);
  const fs::path q = temp_file("truncated");
  for (std::size_t n = 0; n < bytes.size(); n += (n < 600 ? 1 : 97)) {
    write_all(q, std::vector<char>(bytes.begin(), bytes.begin() + std::ptrdiff_t(n)));
    EXPECT_THROW(Archive::open(q, "test.Sample", 3), Error) << "truncated to " << n << " bytes";
  }
  fs::remove(p);
  fs::remove(q);
}

TEST(Archive, TrailingBytesAreAnError) {
  const fs::path p = write_sample("trailing");
  std::vector<char> bytes = read_all(p);
  bytes.push_back(0);
  write_all(p, bytes);
  EXPECT_THROW(Archive::open(p, "test.Sample", 3, Archive::Verify::structure_only), Error);
  fs::remove(p);
}

TEST(Archive, ElementTypesRecordedAsValues) {
  ArchiveWriter w("test.Typed", 1);
  w.add_dtype("scalar", DType::f32);
  w.add_value("not_a_type", std::uint32_t(77));
  const fs::path p = temp_file("typed");
  w.write(p);
  const Archive a = Archive::open(p, "test.Typed", 1);
  EXPECT_EQ(a.dtype("scalar"), DType::f32);
  EXPECT_NO_THROW(a.require_dtype<float>("scalar", "sample"));
  try {
    a.require_dtype<double>("scalar", "sample");
    FAIL() << "f32 accepted as f64";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), p.string() + ": a sample of f32, expected f64");
  }
  EXPECT_THROW(a.dtype("not_a_type"), Error);
  fs::remove(p);
}

TEST(FlatArray, EqualityComparesElements) {
  static const int backing[3] = {1, 2, 3};
  const FlatArray<int> owned(std::vector<int>{1, 2, 3});
  const FlatArray<int> viewed(std::span<const int>(backing), std::make_shared<int>(0));
  EXPECT_EQ(owned, viewed);
  EXPECT_NE(owned, FlatArray<int>(std::vector<int>{1, 2}));
  EXPECT_NE(owned, FlatArray<int>(std::vector<int>{1, 2, 4}));
}

TEST(Archive, EveryFlippedByteIsAnErrorOrHarmlessPadding) {
  const fs::path p = write_sample("flip");
  const std::vector<char> bytes = read_all(p);
  const fs::path q = temp_file("flipped");
  int caught = 0, harmless = 0;
  for (std::size_t i = 0; i < bytes.size(); i += (i < 640 ? 1 : 13)) {
    std::vector<char> bad = bytes;
    bad[i] = char(bad[i] ^ 0x5a);
    write_all(q, bad);
    try {
      const Archive a = Archive::open(q, "test.Sample", 3);
      // Accepted only if every section still reads the same (the byte was padding).
      const FlatArray<float> points = a.array<float>("points", 3001);
      for (std::size_t k = 0; k < points.size(); ++k) ASSERT_EQ(points[k], float(k) + 0.5f) << "byte " << i;
      ASSERT_EQ(a.array<Node>("nodes", 2)[1].end, 20u) << "byte " << i;
      ASSERT_EQ(a.value<std::uint64_t>("leaf_size"), 10u) << "byte " << i;
      ++harmless;
    } catch (const Error&) {
      ++caught;
    }
  }
  EXPECT_GT(caught, 600);
  fs::remove(p);
  fs::remove(q);
}

TEST(Archive, StructureOnlySkipsTheChecksumsButStillChecksBounds) {
  const fs::path p = write_sample("structure_only");
  std::vector<char> bytes = read_all(p);
  bytes.back() = char(bytes.back() ^ 1);  // payload bit: only the checksum sees it
  write_all(p, bytes);
  EXPECT_THROW(Archive::open(p, "test.Sample", 3), Error);
  EXPECT_NO_THROW(Archive::open(p, "test.Sample", 3, Archive::Verify::structure_only));
  bytes.erase(bytes.end() - 9, bytes.end());
  write_all(p, bytes);
  EXPECT_THROW(Archive::open(p, "test.Sample", 3, Archive::Verify::structure_only), Error);
  fs::remove(p);
}

TEST(Archive, BadNamesAndFilesAreErrors) {
  EXPECT_THROW(ArchiveWriter("", 1), Error);
  EXPECT_THROW(ArchiveWriter(std::string(32, 'k'), 1), Error);
  ArchiveWriter w("test.Sample", 1);
  std::vector<int> v{1};
  w.add("a", v);
  EXPECT_THROW(w.add("a", v), Error);
  EXPECT_THROW(w.add(std::string(40, 'n'), v), Error);
  EXPECT_THROW(w.write("/nonexistent-dir/x.geods"), Error);
  EXPECT_THROW(Archive::open("/nonexistent-dir/x.geods", "test.Sample", 1), Error);
  EXPECT_THROW(Archive::open(fs::temp_directory_path(), "test.Sample", 1), Error);  // a directory
  const fs::path q = temp_file("not_an_archive");
  write_all(q, std::vector<char>(200, 'x'));
  EXPECT_THROW(Archive::peek(q), Error);
  fs::remove(q);
}

TEST(Archive, CheckRethrowsAStructuresErrorNamingTheFile) {
  const fs::path p = write_sample("check");
  const Archive a = Archive::open(p, "test.Sample", 3);
  EXPECT_NO_THROW(a.check([] {}));
  try {
    a.check([] { throw Error("node 3: bad child index"); });
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), p.string() + ": node 3: bad child index");
  }
  fs::remove(p);
}

}  // namespace
}  // namespace geods
