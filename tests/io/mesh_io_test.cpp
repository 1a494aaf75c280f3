#include "geods/io/mesh_io.hpp"

#include <zlib.h>

#include <cmath>
#include <limits>

#include "io_test_util.hpp"

namespace geods::io {
namespace {

using test::expect_error;
using test::TempDir;

// A closed, outward-oriented unit cube: 8 vertices, 12 triangles.
TriMesh cube() {
  TriMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1) + 0.1f);
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

// Same triangles up to vertex renumbering (readers of unindexed formats may reorder).
void expect_same_geometry(const TriMesh& a, const TriMesh& b) {
  ASSERT_EQ(a.num_triangles(), b.num_triangles());
  EXPECT_NEAR(a.signed_volume(), b.signed_volume(), 1e-5);
  EXPECT_NEAR(a.surface_area(), b.surface_area(), 1e-5);
  EXPECT_TRUE(b.validate().closed_manifold());
}

TEST(MeshIo, RoundTripsEveryWriter) {
  TempDir dir;
  const TriMesh m = cube();
  for (const auto& [name, enc] : {std::pair{"c.ply", MeshEncoding::binary}, std::pair{"ca.ply", MeshEncoding::ascii},
                                  std::pair{"c.obj", MeshEncoding::ascii}, std::pair{"c.stl", MeshEncoding::binary},
                                  std::pair{"ca.stl", MeshEncoding::ascii}}) {
    SCOPED_TRACE(name);
    write_mesh(dir / name, m, enc);
    const TriMesh r = read_mesh(dir / name);
    EXPECT_EQ(r.num_vertices(), 8u);  // STL's coincident vertices are merged
    expect_same_geometry(m, r);
  }
  // PLY keeps the vertex order and the triangles exactly.
  const TriMesh r = read_mesh(dir / "c.ply");
  EXPECT_EQ(r.vertices, m.vertices);
  EXPECT_EQ(r.triangles, m.triangles);
}

TEST(MeshIo, WritesAndReadsNormals) {
  TempDir dir;
  TriMesh m = cube();
  for (const Vec3f& v : m.vertices) m.normals.push_back((v - Vec3f(0.5f, 0.5f, 0.6f)).normalized());
  for (const char* name : {"n.ply", "n.obj"}) {
    write_mesh(dir / name, m);
    const TriMesh r = read_mesh(dir / name);
    ASSERT_EQ(r.normals.size(), r.vertices.size()) << name;
    for (std::size_t i = 0; i < r.vertices.size(); ++i)
      EXPECT_NEAR((r.normals[i] - (r.vertices[i] - Vec3f(0.5f, 0.5f, 0.6f)).normalized()).norm(), 0, 1e-5);
  }
}

TEST(MeshIo, ReadsRealFiles) {
  const TriMesh bunny = read_mesh(test::data_path("bunny.ply"));
  EXPECT_EQ(bunny.num_vertices(), 1839u);
  EXPECT_EQ(bunny.num_triangles(), 3674u);
  EXPECT_TRUE(bunny.validate().valid());
  const TriMesh teapot = read_mesh(test::data_path("teapot.obj"));
  EXPECT_EQ(teapot.num_triangles(), 992u);
  EXPECT_TRUE(teapot.validate().valid());
}

// COFF, NOFF, CNOFF and STOFF carry values after x y z; faces may end in a colour.
// The oracle: the same square as plain OFF, read by the strict parser.
TEST(MeshIo, ReadsOffVariantsIgnoringColoursAndNormals) {
  TempDir dir;
  test::write_text(dir / "plain.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
  const TriMesh plain = read_mesh(dir / "plain.off");
  const std::pair<const char*, const char*> variants[] = {
      {"COFF", "0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n1 1 0 0 0 255 255\n0 1 0 9 9 9 255\n"},
      {"NOFF", "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n"},
      {"CNOFF", "0 0 0 0 0 1 1 0 0 1\n1 0 0 0 0 1 1 0 0 1\n1 1 0 0 0 1 1 0 0 1\n0 1 0 0 0 1 1 0 0 1\n"},
      {"STOFF", "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n"},
  };
  for (const auto& [keyword, vertices] : variants) {
    // Face colours (3 or 4 values, ints or floats) end the face lines.
    test::write_text(dir / "v.off", std::string(keyword) + "\n4 2 0\n" + vertices + "3 0 1 2 255 0 0\n3 0 2 3 0.5 0.5 0.5 1\n");
    const TriMesh m = read_mesh(dir / "v.off");
    EXPECT_EQ(m.vertices, plain.vertices) << keyword;
    EXPECT_EQ(m.triangles, plain.triangles) << keyword;
  }
  // Plain OFF with face colours: the colours used to be read as the next face's size.
  test::write_text(dir / "fc.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 3 1 2\n3 0 2 3 200 200 200\n");
  EXPECT_EQ(read_mesh(dir / "fc.off").triangles, plain.triangles);
  test::write_text(dir / "4d.off", "4OFF\n3 1 0\n0 0 0 0\n1 0 0 0\n0 1 0 0\n3 0 1 2\n");
  expect_error(dir / "4d.off", [&] { read_mesh(dir / "4d.off"); }, "4OFF");
  test::write_text(dir / "b.off", "OFF BINARY\n");
  expect_error(dir / "b.off", [&] { read_mesh(dir / "b.off"); }, "binary OFF");
  // A COFF whose vertex lines are short is an error, not a shifted mesh.
  test::write_text(dir / "short.off", "COFF\n3 1 0\n0 0\n1 0 0 1 1 1\n0 1 0 1 1 1\n3 0 1 2\n");
  expect_error(dir / "short.off", [&] { read_mesh(dir / "short.off"); });
}

TEST(MeshIo, MeshNamesIncludeEveryGzipMesh) {
  for (const char* name : {"a.ply", "a.OBJ", "a.stl", "a.off", "a.gltf", "a.glb", "a.stl.gz", "a.obj.gz", "a.ply.gz", "a.off.gz"})
    EXPECT_TRUE(is_mesh_name(name)) << name;
  for (const char* name : {"a.nii.gz", "a.gz", "a.npy", "a.png", "a", "a.csv"}) EXPECT_FALSE(is_mesh_name(name)) << name;
}

TEST(MeshIo, ReadsOffGzipAndGltf) {
  TempDir dir;
  const std::string off = "OFF\n# a square\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
  test::write_text(dir / "q.off", off);
  const TriMesh q = read_mesh(dir / "q.off");
  EXPECT_EQ(q.num_vertices(), 4u);
  EXPECT_EQ(q.num_triangles(), 2u);  // the quad is triangulated
  EXPECT_NEAR(q.surface_area(), 1.0, 1e-6);

  // .off.gz and .ply.gz are inflated in memory.
  for (const char* name : {"q.off", "c.ply"}) {
    if (std::string(name) == "c.ply") write_mesh(dir / name, cube());
    const auto raw = test::read_bytes(dir / name);
    gzFile gz = gzopen((dir / (std::string(name) + ".gz")).c_str(), "wb");
    gzwrite(gz, raw.data(), unsigned(raw.size()));
    gzclose(gz);
    EXPECT_EQ(read_mesh(dir / (std::string(name) + ".gz")).num_triangles(), std::string(name) == "q.off" ? 2u : 12u);
  }

  // A glTF 2.0 triangle with its buffer embedded as a data URI: 3 float3 positions, 3 u16 indices.
  std::vector<std::uint8_t> buf;
  auto put = [&](const void* p, std::size_t n) { buf.insert(buf.end(), (const std::uint8_t*)p, (const std::uint8_t*)p + n); };
  const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::uint16_t idx[4] = {0, 1, 2, 0};
  put(pos, sizeof(pos));
  put(idx, sizeof(idx));
  static const char* b64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string enc;
  for (std::size_t i = 0; i < buf.size(); i += 3) {
    const std::uint32_t n = (buf[i] << 16) | ((i + 1 < buf.size() ? buf[i + 1] : 0) << 8) | (i + 2 < buf.size() ? buf[i + 2] : 0);
    enc += b64[(n >> 18) & 63];
    enc += b64[(n >> 12) & 63];
    enc += i + 1 < buf.size() ? b64[(n >> 6) & 63] : '=';
    enc += i + 2 < buf.size() ? b64[n & 63] : '=';
  }
  const std::string gltf = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0,"translation":[0,0,5]}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
"buffers":[{"byteLength":44,"uri":"data:application/octet-stream;base64,)" + enc + R"("}],
"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}]})";
  test::write_text(dir / "t.gltf", gltf);
  const TriMesh t = read_mesh(dir / "t.gltf");
  ASSERT_EQ(t.num_triangles(), 1u);
  EXPECT_FLOAT_EQ(t.vertices[0].z(), 5.0f);  // the node's transform is applied
}

TEST(MeshIo, MalformedFilesThrowNamingTheFile) {
  TempDir dir;
  expect_error(dir / "missing.ply", [&] { read_mesh(dir / "missing.ply"); }, "no such file");
  expect_error(dir.path(), [&] { read_mesh(dir.path()); });
  for (const char* name : {"e.ply", "e.obj", "e.stl", "e.off", "e.glb", "e.gltf"}) {
    test::write_text(dir / name, "");
    expect_error(dir / name, [&] { read_mesh(dir / name); }, "empty");
  }
  test::write_text(dir / "m.xyz", "1 2 3\n");
  expect_error(dir / "m.xyz", [&] { read_mesh(dir / "m.xyz"); }, "unsupported");
  test::write_text(dir / "w.ply", "plx\nformat ascii 1.0\nend_header\n");
  expect_error(dir / "w.ply", [&] { read_mesh(dir / "w.ply"); }, "magic");
  test::write_text(dir / "w.off", "NOT\n1 1 0\n");
  expect_error(dir / "w.off", [&] { read_mesh(dir / "w.off"); }, "magic");
  test::write_text(dir / "w.stl", "garbage that is neither binary nor ascii STL");
  expect_error(dir / "w.stl", [&] { read_mesh(dir / "w.stl"); });
  test::write_bytes(dir / "w.glb", {'g', 'l', 'T', 'F', 2, 0, 0, 0, 0xff, 0xff, 0xff, 0x7f});
  expect_error(dir / "w.glb", [&] { read_mesh(dir / "w.glb"); }, "truncated");

  // Absurd counts in a small file are rejected before Assimp sees them.
  test::write_text(dir / "big.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
                                    "property float y\nproperty float z\nelement face 1\nproperty list uchar int v\nend_header\n");
  expect_error(dir / "big.ply", [&] { read_mesh(dir / "big.ply"); }, "truncated");
  test::write_text(dir / "big.off", "OFF\n1000000000 1000000000 0\n0 0 0\n");
  expect_error(dir / "big.off", [&] { read_mesh(dir / "big.off"); }, "truncated");
  std::vector<std::uint8_t> stl(84 + 50, 0);
  stl[80] = 0xff;
  stl[81] = 0xff;
  test::write_bytes(dir / "big.stl", stl);
  expect_error(dir / "big.stl", [&] { read_mesh(dir / "big.stl"); }, "truncated");

  // NaN coordinates and out-of-range indices.
  test::write_text(dir / "nan.obj", "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n");
  expect_error(dir / "nan.obj", [&] { read_mesh(dir / "nan.obj"); });
  test::write_text(dir / "nan.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                    "0 0 0\n1 0 inf\n0 1 0\n3 0 1 2\n");
  expect_error(dir / "nan.ply", [&] { read_mesh(dir / "nan.ply"); });
  test::write_text(dir / "idx.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                    "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  expect_error(dir / "idx.ply", [&] { read_mesh(dir / "idx.ply"); });
  test::write_text(dir / "idx.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  expect_error(dir / "idx.obj", [&] { read_mesh(dir / "idx.obj"); });
  test::write_text(dir / "idx.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n");
  expect_error(dir / "idx.off", [&] { read_mesh(dir / "idx.off"); });
  test::write_text(dir / "pts.obj", "v 0 0 0\nv 1 0 0\n");
  expect_error(dir / "pts.obj", [&] { read_mesh(dir / "pts.obj"); });
  test::write_text(dir / "bad.gz.ply.gz", "not gzip");
  expect_error(dir / "bad.gz.ply.gz", [&] { read_mesh(dir / "bad.gz.ply.gz"); }, "gzip");

  // Truncations of files with counts in their headers.
  write_mesh(dir / "c.ply", cube());
  write_mesh(dir / "c.stl", cube());
  write_mesh(dir / "ca.ply", cube(), MeshEncoding::ascii);
  auto read = [](const std::filesystem::path& f) { read_mesh(f); };
  test::expect_truncations_fail(dir.path(), "cut.ply", test::read_bytes(dir / "c.ply"), read);
  test::expect_truncations_fail(dir.path(), "cut.stl", test::read_bytes(dir / "c.stl"), read);
  auto ascii = test::read_bytes(dir / "ca.ply");
  ascii.resize(ascii.size() - 20);  // strictly: cut inside the faces
  test::expect_truncations_fail(dir.path(), "cuta.ply", ascii, read);
  test::expect_truncations_fail(dir.path(), "cutbunny.ply", test::read_bytes(test::data_path("bunny.ply")), read);
  write_mesh(dir / "c.obj", cube());
  test::expect_truncations_fail(dir.path(), "cut.obj", test::read_bytes(dir / "c.obj"), read, false);
}

TEST(MeshIo, WriterRejectsBadMeshes) {
  TempDir dir;
  TriMesh m = cube();
  m.triangles.push_back({0, 1, 99});
  expect_error(dir / "x.ply", [&] { write_mesh(dir / "x.ply", m); }, "out of range");
  expect_error(dir / "x.off", [&] { write_mesh(dir / "x.off", cube()); }, "unsupported");
  expect_error(dir / "nodir" / "x.ply", [&] { write_mesh(dir / "nodir" / "x.ply", cube()); });
  // Meshes read_mesh would refuse are refused before anything is written, in every format.
  const float inf = std::numeric_limits<float>::infinity();
  for (const char* name : {"x.ply", "x.obj", "x.stl"}) {
    for (const Vec3f& bad : {Vec3f(0, std::nanf(""), 0), Vec3f(inf, 0, 0), Vec3f(0, 0, -inf)}) {
      TriMesh nan = cube();
      nan.vertices[5] = bad;
      expect_error(dir / name, [&] { write_mesh(dir / name, nan); }, "vertex 5 has a non-finite coordinate");
      EXPECT_FALSE(std::filesystem::exists(dir / name));
    }
    TriMesh normals = cube();
    normals.normals.assign(8, Vec3f(0, 0, 1));
    normals.normals[2].x() = std::nanf("");
    expect_error(dir / name, [&] { write_mesh(dir / name, normals); }, "normal 2");
    TriMesh index = cube();
    index.triangles[3][1] = 8;
    expect_error(dir / name, [&] { write_mesh(dir / name, index, MeshEncoding::ascii); }, "out of range");
    EXPECT_FALSE(std::filesystem::exists(dir / name));
  }
}

}  // namespace
}  // namespace geods::io
