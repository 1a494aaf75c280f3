// Collections: a directory tree of every mesh format, a zip archive and a
// Sweet Home 3D library (data/furniture.sh3f), labels from a CSV or the
// catalog, and unreadable members skipped by name and counted.
#include <gtest/gtest.h>
#include <zip.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "common/data_files.hpp"
#include "geods/core/error.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/shape/collection.hpp"
#include "geods/shape/retrieval.hpp"
#include "shape/test_meshes.hpp"

namespace geods::shape {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("geods_shape_collection_" + std::to_string(::getpid()));
  TempDir() {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

void write_text(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

DescriptorOptions options() {
  DescriptorOptions o;
  o.distribution.samples = 8192;
  o.distribution.bins = 16;
  return o;
}

void put(const fs::path& p, const TriMesh& mesh) {
  fs::create_directories(p.parent_path());
  io::write_mesh(p, mesh);
}

// A tree with every written format, an OFF and a .gz, plus broken members.
void make_tree(const fs::path& root) {
  put(root / "round/sphere.ply", testing::icosphere(2));
  put(root / "round/sphere_big.stl", testing::transformed(testing::icosphere(3), Eigen::Matrix3f::Identity(), {1, 1, 1}, 3));
  put(root / "boxy/cube.obj", testing::cube());
  write_text(root / "boxy/cube2.off", "OFF\n8 12 0\n0 0 0\n2 0 0\n0 2 0\n2 2 0\n0 0 2\n2 0 2\n0 2 2\n2 2 2\n"
                                      "3 0 2 1\n3 1 2 3\n3 4 5 6\n3 5 7 6\n3 0 1 4\n3 1 5 4\n"
                                      "3 2 6 3\n3 3 6 7\n3 0 4 2\n3 2 4 6\n3 1 3 5\n3 3 7 5\n");
  write_text(root / "broken/garbage.ply", "ply\nthis is not a mesh\n");
  write_text(root / "broken/empty.stl", "");
  write_text(root / "broken/flat.obj", "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n");  // zero area
  write_text(root / "notes.txt", "not a mesh: ignored\n");
}

TEST(ShapeCollection, DirectoryTreeSkipsUnreadableMembersByName) {
  TempDir dir;
  make_tree(dir.path);
  write_text(dir.path / "labels.csv", "path,label\nround/sphere.ply,round\n./round/sphere_big.stl,round\n"
                                      "boxy/cube.obj,boxy\n\"boxy/cube2.off\",boxy\nmissing.ply,ghost\n");
  const ShapeCollection c = ShapeCollection::open(dir.path, dir.path / "labels.csv");
  EXPECT_EQ(c.kind(), CollectionKind::directory);
  std::vector<std::string> names;
  for (const auto& e : c.entries()) names.push_back(e.name);
  EXPECT_EQ(names, (std::vector<std::string>{"boxy/cube.obj", "boxy/cube2.off", "broken/empty.stl", "broken/flat.obj",
                                             "broken/garbage.ply", "round/sphere.ply", "round/sphere_big.stl"}));
  ASSERT_EQ(c.warnings().size(), 1u);
  EXPECT_NE(c.warnings()[0].find("missing.ply"), std::string::npos);
  const CollectionIndex index = index_collection(c, options());
  ASSERT_EQ(index.skipped.size(), 3u);
  EXPECT_EQ(index.skipped[0].name, "broken/empty.stl");
  EXPECT_EQ(index.skipped[1].name, "broken/flat.obj");
  EXPECT_NE(index.skipped[1].reason.find("zero area"), std::string::npos) << index.skipped[1].reason;
  EXPECT_EQ(index.skipped[2].name, "broken/garbage.ply");
  const ShapeDatabase& db = index.database;
  ASSERT_EQ(db.size(), 4u);
  EXPECT_EQ(db.labels(), (std::vector<std::string>{"boxy", "boxy", "round", "round"}));
  // The two spheres and the two cubes (another size, another format) find each other.
  const auto scores = evaluate_retrieval(db, 1);
  EXPECT_EQ(scores.queries, 4u);
  EXPECT_DOUBLE_EQ(scores.nn_rate, 1.0);
  EXPECT_EQ(db.query(io::read_mesh(dir.path / "round/sphere.ply"), 1).front().name, "round/sphere.ply");
}

TEST(ShapeCollection, ZipArchiveReadsMembersInMemory) {
  TempDir dir;
  make_tree(dir.path / "tree");
  const fs::path zip_path = dir.path / "meshes.zip";
  int error = 0;
  zip_t* z = zip_open(zip_path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  ASSERT_NE(z, nullptr);
  std::vector<std::string> keep;  // the buffers must live until zip_close
  for (const char* name : {"round/sphere.ply", "boxy/cube.obj", "broken/garbage.ply", "notes.txt"}) {
    keep.push_back(read_bytes(dir.path / "tree" / name));
    zip_source_t* s = zip_source_buffer(z, keep.back().data(), keep.back().size(), 0);
    ASSERT_GE(zip_file_add(z, name, s, ZIP_FL_OVERWRITE), 0);
  }
  ASSERT_EQ(zip_close(z), 0);
  const ShapeCollection c = ShapeCollection::open(zip_path);
  EXPECT_EQ(c.kind(), CollectionKind::zip);
  ASSERT_EQ(c.size(), 3u);
  const TriMesh cube = c.read(0);
  EXPECT_EQ(c.entries()[0].name, "boxy/cube.obj");
  EXPECT_EQ(cube.triangles.size(), 12u);
  const CollectionIndex index = index_collection(c, options());
  ASSERT_EQ(index.skipped.size(), 1u);
  EXPECT_EQ(index.skipped[0].name, "broken/garbage.ply");
  EXPECT_NE(index.skipped[0].reason.find("garbage.ply"), std::string::npos);
  EXPECT_EQ(index.database.size(), 2u);
  // A file that is not a zip, one that is truncated, a path that is nothing.
  write_text(dir.path / "fake.zip", "PK but no archive");
  EXPECT_THROW(ShapeCollection::open(dir.path / "fake.zip"), Error);
  const std::string bytes = read_bytes(zip_path);
  write_text(dir.path / "cut.zip", bytes.substr(0, bytes.size() / 2));
  EXPECT_THROW(ShapeCollection::open(dir.path / "cut.zip"), Error);
  EXPECT_THROW(ShapeCollection::open(dir.path / "nothing"), Error);
  EXPECT_THROW(ShapeCollection::open(dir.path / "tree/notes.txt"), Error);
}

TEST(ShapeCollection, SweetHome3DLibraryLabelsByCategory) {
  const ShapeCollection c = ShapeCollection::open(test::data_path("furniture.sh3f"));
  EXPECT_EQ(c.kind(), CollectionKind::sh3f);
  ASSERT_EQ(c.size(), 14u);
  EXPECT_TRUE(c.warnings().empty());
  std::map<std::string, int> per_label;
  for (const auto& e : c.entries()) per_label[e.label]++;
  EXPECT_EQ(per_label, (std::map<std::string, int>{{"Exterior", 5}, {"Kitchen", 4}, {"Lights", 1}, {"Miscellaneous", 4}}));
  EXPECT_EQ(c.entries()[0].name, "blendswap-cc-0/pallet/pallet.obj");  // model#29, the lowest number
  EXPECT_EQ(c.entries()[0].title, "Pallet");
  const CollectionIndex index = index_collection(c, options());
  EXPECT_TRUE(index.skipped.empty());
  EXPECT_EQ(index.database.size(), 14u);
  const RetrievalScores s = evaluate_retrieval(index.database, 3);
  EXPECT_EQ(s.queries, 13u);  // the one light has no other member of its class
  EXPECT_EQ(s.classes, 3u);
  EXPECT_GT(s.nn_rate, 0.3);  // better than chance (about 0.3 for these class sizes)
  // A CSV overrides the catalog.
  TempDir dir;
  write_text(dir.path / "l.csv", "blendswap-cc-0/rock1/rock1.obj,stone\n");
  const ShapeCollection relabelled = ShapeCollection::open(test::data_path("furniture.sh3f"), dir.path / "l.csv");
  for (const auto& e : relabelled.entries())
    EXPECT_EQ(e.label == "stone", e.name == "blendswap-cc-0/rock1/rock1.obj") << e.name;
}

TEST(ShapeCollection, LabelsCsvErrorsNameTheLine) {
  TempDir dir;
  write_text(dir.path / "a.csv", "path,label\na.ply,x\nb.ply\n");
  try {
    read_labels_csv(dir.path / "a.csv");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("a.csv:3"), std::string::npos) << e.what();
  }
  write_text(dir.path / "b.csv", "\"a,1.ply\",\"x \"\"y\"\"\"\n# comment\n\n");
  const auto rows = read_labels_csv(dir.path / "b.csv");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].first, "a,1.ply");
  EXPECT_EQ(rows[0].second, "x \"y\"");
  EXPECT_THROW(read_labels_csv(dir.path / "none.csv"), Error);
  make_tree(dir.path / "t");
  write_text(dir.path / "c.csv", "nothing.ply,x\n");
  EXPECT_THROW(ShapeCollection::open(dir.path / "t", dir.path / "c.csv"), Error);
}

}  // namespace
}  // namespace geods::shape
