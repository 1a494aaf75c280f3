#include <assimp/DefaultIOSystem.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#include "file_util.hpp"
#include "geods/core/weld.hpp"
#include "geods/io/mesh_io.hpp"
#include "ply.hpp"

namespace geods::io {

namespace fs = std::filesystem;
using detail::fail;

namespace {

// Largest .gz mesh we inflate: far above any real mesh, but a bound on what a
// hostile file can make us allocate.
constexpr std::size_t max_inflated_mesh = std::size_t(8) << 30;

// Lets Assimp open side files (OBJ materials, glTF buffers) only if they are
// regular files, so a hostile "mtllib /dev/zero" cannot hang the reader.
class RegularFilesOnly : public Assimp::DefaultIOSystem {
 public:
  bool Exists(const char* file) const override {
    std::error_code ec;
    return fs::is_regular_file(file, ec);
  }
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) return nullptr;
    return DefaultIOSystem::Open(file, mode);
  }
};

// PLY, OFF and STL are read by our own parsers: they check every count, index
// and number (Assimp silently accepts truncated PLY faces and out-of-range OFF
// indices, and leaks on malformed STL) and keep the file's vertex order.
// Assimp reads OBJ and glTF.
TriMesh mesh_from_ply(const fs::path& path, std::span<const std::uint8_t> bytes) {
  const detail::PlyData ply = detail::read_ply(path, bytes);
  if (ply.dim != 3) fail(path, "vertex element has no z property");
  TriMesh mesh;
  const std::size_t n = ply.positions.size() / 3;
  if (n > std::numeric_limits<std::uint32_t>::max()) fail(path, "more than 2^32 vertices");
  mesh.vertices.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      const double v = ply.positions[3 * i + std::size_t(c)];
      if (!detail::fits_float(v)) fail(path, "vertex " + std::to_string(i) + " is out of float range");
      mesh.vertices[i][c] = float(v);
    }
  }
  for (std::size_t i = 0; i + 2 < ply.normals.size(); i += 3)
    mesh.normals.emplace_back(ply.normals[i], ply.normals[i + 1], ply.normals[i + 2]);
  if (ply.triangles.empty()) fail(path, "no triangles (no face element with vertex_indices)");
  mesh.triangles.resize(ply.triangles.size() / 3);
  std::memcpy(mesh.triangles.data(), ply.triangles.data(), ply.triangles.size() * sizeof(std::uint32_t));
  return mesh;
}

// The whitespace-separated tokens of a text file; '#' starts a comment if `comments`.
class Tokens {
 public:
  Tokens(std::string_view text, bool comments) : s_(text), comments_(comments) {}
  bool next(std::string_view& token) {
    for (;;) {
      while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
      if (comments_ && i_ < s_.size() && s_[i_] == '#') {
        while (i_ < s_.size() && s_[i_] != '\n') ++i_;
        continue;
      }
      break;
    }
    if (i_ >= s_.size()) return false;
    const std::size_t start = i_;
    while (i_ < s_.size() && !std::isspace(static_cast<unsigned char>(s_[i_])) && !(comments_ && s_[i_] == '#')) ++i_;
    token = s_.substr(start, i_ - start);
    return true;
  }
  std::size_t remaining() const { return s_.size() - i_; }
  void skip_line() {
    while (i_ < s_.size() && s_[i_] != '\n') ++i_;
  }

 private:
  std::string_view s_;
  bool comments_;
  std::size_t i_ = 0;
};

TriMesh mesh_from_off(const fs::path& path, std::string_view text) {
  Tokens tokens(text, true);
  std::string_view t;
  if (!tokens.next(t) || t.size() < 3 || t.substr(t.size() - 3) != "OFF") fail(path, "not an OFF file (wrong magic)");
  // Variants: ST (texture coordinates), C (colours) and N (normals) before OFF
  // add values after each vertex's x y z, which are skipped with the rest of
  // its line. 4OFF and nOFF (other dimensions) and binary OFF are refused.
  const std::string_view prefix = t.substr(0, t.size() - 3);
  const bool variant = !prefix.empty();
  if (variant && prefix != "C" && prefix != "N" && prefix != "NC" && prefix != "CN" && prefix != "ST" &&
      prefix != "STC" && prefix != "STN" && prefix != "STNC" && prefix != "STCN")
    fail(path, "unsupported OFF variant '" + std::string(t.substr(0, 20)) +
                   "' (OFF, COFF, NOFF, CNOFF and STOFF are read; 4OFF and nOFF are not)");
  auto count = [&](const std::string& what) {
    std::size_t v = 0;
    if (!tokens.next(t)) fail(path, "truncated: file ends before the " + what);
    if (!detail::parse_size(t, v)) fail(path, "malformed " + what);
    return v;
  };
  {
    Tokens peek = tokens;
    if (peek.next(t) && t == "BINARY") fail(path, "binary OFF is not supported (ascii OFF only)");
  }
  const std::size_t nv = count("vertex count"), nf = count("face count");
  count("edge count");
  // Every number takes a digit and a separator: the counts are bounded by the bytes left.
  const std::size_t rest = tokens.remaining();
  if (nv > rest / 6 || nf > rest / 8 || nv * 6 + nf * 8 > rest + 1)
    fail(path, "truncated: header declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                   " faces but only " + std::to_string(rest) + " bytes follow");
  TriMesh mesh;
  mesh.vertices.resize(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    for (int c = 0; c < 3; ++c) {
      double v = 0;
      if (!tokens.next(t)) fail(path, "truncated: file ends in vertex " + std::to_string(i) + " of " + std::to_string(nv));
      if (!detail::parse_double(t, v)) fail(path, "malformed number in vertex " + std::to_string(i));
      if (!detail::fits_float(v)) fail(path, "vertex " + std::to_string(i) + " has a non-finite or out-of-range coordinate");
      mesh.vertices[i][c] = float(v);
    }
    if (!mesh.vertices[i].allFinite()) fail(path, "vertex " + std::to_string(i) + " has a non-finite coordinate");
    if (variant) tokens.skip_line();  // normals, colours, texture coordinates
  }
  for (std::size_t f = 0; f < nf; ++f) {
    const std::size_t k = count("size of face " + std::to_string(f) + " of " + std::to_string(nf));
    if (k < 3 || k > tokens.remaining()) fail(path, "face " + std::to_string(f) + " has a bad vertex count " + std::to_string(k));
    std::uint32_t first = 0, prev = 0;
    for (std::size_t j = 0; j < k; ++j) {
      std::size_t v = 0;
      if (!tokens.next(t)) fail(path, "truncated: file ends in face " + std::to_string(f) + " of " + std::to_string(nf));
      if (!detail::parse_size(t, v) || v >= nv)
        fail(path, "face " + std::to_string(f) + " has vertex index '" + std::string(t.substr(0, 20)) + "' out of range (" +
                       std::to_string(nv) + " vertices)");
      if (j == 0) first = std::uint32_t(v);
      else if (j >= 2) mesh.triangles.push_back({first, prev, std::uint32_t(v)});
      prev = std::uint32_t(v);
    }
    tokens.skip_line();  // a face's colour, if any, ends its line: not kept
  }
  if (mesh.triangles.empty()) fail(path, "no triangles");
  return mesh;
}

// OBJ has no counts to check, but Assimp reads "nan" and "inf" as numbers:
// scan the vertex lines for them ourselves.
void check_obj(const fs::path& path, std::string_view text) {
  detail::LineReader lines(text);
  std::string_view line;
  while (lines.next(line)) {
    const auto f = detail::split_fields(line);
    if (f.empty() || (f[0] != "v" && f[0] != "vn")) continue;
    for (std::size_t i = 1; i < f.size() && i < 4; ++i) {
      double v = 0;
      if (!detail::parse_double(f[i], v) || !std::isfinite(v))
        fail(path, "line " + std::to_string(lines.line_number()) + ": bad coordinate '" + std::string(f[i].substr(0, 40)) + "'");
    }
  }
}

// STL: facets with their own corners, read as three vertices each;
// merge_corners() then makes coincident corners (same floats, -0 and +0 alike)
// one vertex, numbered in order of first use.
void add_facet(const fs::path& path, TriMesh& mesh, const Vec3f (&corners)[3], std::size_t facet) {
  const auto first = std::uint32_t(mesh.vertices.size());
  for (int c = 0; c < 3; ++c) {
    if (!corners[c].allFinite()) fail(path, "facet " + std::to_string(facet) + " has a non-finite coordinate");
    mesh.vertices.push_back(corners[c]);
  }
  mesh.triangles.push_back({first, first + 1, first + 2});
}

TriMesh merge_corners(TriMesh mesh) {
  const std::vector<std::uint32_t> id = weld(mesh.vertices);
  std::vector<std::uint32_t> number(id.size());
  std::uint32_t kept = 0;
  for (std::size_t v = 0; v < id.size(); ++v) {
    if (id[v] != v) {
      number[v] = number[id[v]];  // id[v] < v: numbered already
      continue;
    }
    number[v] = kept;
    mesh.vertices[kept++] = mesh.vertices[v] + Vec3f::Zero();  // -0 + 0 = +0
  }
  mesh.vertices.resize(kept);
  for (TriMesh::Triangle& t : mesh.triangles)
    for (std::uint32_t& c : t) c = number[c];
  return mesh;
}

TriMesh mesh_from_stl(const fs::path& path, std::span<const std::uint8_t> bytes) {
  TriMesh mesh;
  // Binary if the size matches the facet count exactly: binary files may also start with "solid".
  if (bytes.size() >= 84) {
    const std::uint64_t n = detail::load<std::uint32_t>(bytes.data() + 80, false);
    if (84 + 50 * n == bytes.size()) {
      mesh.triangles.reserve(n);
      for (std::size_t f = 0; f < n; ++f) {
        const std::uint8_t* p = bytes.data() + 84 + 50 * f + 12;
        Vec3f corners[3];
        for (int c = 0; c < 3; ++c)
          for (int k = 0; k < 3; ++k) corners[c][k] = detail::load<float>(p + 12 * c + 4 * k, false);
        add_facet(path, mesh, corners, f);
      }
      if (mesh.triangles.empty()) fail(path, "no triangles (binary STL with 0 facets)");
      return merge_corners(std::move(mesh));
    }
  }
  const std::string_view text = detail::as_text(bytes);
  if (detail::trim(text.substr(0, 512)).substr(0, 5) != "solid") {
    if (bytes.size() >= 84)
      fail(path, "truncated binary STL: header declares " + std::to_string(detail::load<std::uint32_t>(bytes.data() + 80, false)) +
                     " facets (" + std::to_string(84 + 50 * std::uint64_t(detail::load<std::uint32_t>(bytes.data() + 80, false))) +
                     " bytes), file has " + std::to_string(bytes.size()));
    fail(path, "not an STL file (too short for binary, no 'solid' for ascii)");
  }
  Tokens tokens(text, false);
  std::string_view t;
  auto expect = [&](std::string_view word) {
    if (!tokens.next(t)) fail(path, "truncated: file ends in facet " + std::to_string(mesh.triangles.size()) + " (expected '" + std::string(word) + "')");
    if (t != word)
      fail(path, "malformed ascii STL: expected '" + std::string(word) + "' in facet " + std::to_string(mesh.triangles.size()) +
                     ", found '" + std::string(t.substr(0, 30)) + "'");
  };
  auto number = [&] {
    double v = 0;
    if (!tokens.next(t)) fail(path, "truncated: file ends in facet " + std::to_string(mesh.triangles.size()));
    if (!detail::parse_double(t, v) || !detail::fits_float(v))
      fail(path, "bad number '" + std::string(t.substr(0, 30)) + "' in facet " + std::to_string(mesh.triangles.size()));
    return float(v);
  };
  bool in_solid = false, ended = false;
  while (tokens.next(t)) {
    if (t == "solid") {
      tokens.skip_line();  // the solid's name
      in_solid = true;
    } else if (t == "endsolid") {
      tokens.skip_line();
      in_solid = false;
      ended = true;
    } else if (t == "facet" && in_solid) {
      expect("normal");
      for (int k = 0; k < 3; ++k) number();
      expect("outer");
      expect("loop");
      Vec3f corners[3];
      for (int c = 0; c < 3; ++c) {
        expect("vertex");
        for (int k = 0; k < 3; ++k) corners[c][k] = number();
      }
      expect("endloop");
      expect("endfacet");
      add_facet(path, mesh, corners, mesh.triangles.size());
    } else {
      fail(path, "malformed ascii STL: unexpected '" + std::string(t.substr(0, 30)) + "' after facet " + std::to_string(mesh.triangles.size()));
    }
  }
  if (!ended) fail(path, "truncated: no 'endsolid'");
  if (mesh.triangles.empty()) fail(path, "no triangles");
  return merge_corners(std::move(mesh));
}

void check_glb(const fs::path& path, std::span<const std::uint8_t> bytes) {
  if (bytes.size() < 12 || std::string_view(detail::as_text(bytes.first(4))) != "glTF")
    fail(path, "not a GLB file (wrong magic)");
  const std::uint32_t length = detail::load<std::uint32_t>(bytes.data() + 8, false);
  if (length > bytes.size())
    fail(path, "truncated: GLB header declares " + std::to_string(length) + " bytes, file has " + std::to_string(bytes.size()));
}

void pre_validate(const fs::path& path, const std::string& ext, std::span<const std::uint8_t> bytes) {
  if (bytes.empty()) fail(path, "empty file");
  if (ext == ".obj") check_obj(path, detail::as_text(bytes));
  else if (ext == ".glb") check_glb(path, bytes);
}

bool supported(const std::string& ext) {
  for (const char* e : {".ply", ".obj", ".stl", ".off", ".gltf", ".glb"})
    if (ext == e) return true;
  return false;
}

TriMesh convert(const fs::path& path, const aiScene& scene) {
  TriMesh mesh;
  std::size_t total_vertices = 0;
  bool all_normals = true;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* am = scene.mMeshes[m];
    if (!am || !am->mVertices) continue;
    total_vertices += am->mNumVertices;
    all_normals = all_normals && am->mNormals != nullptr;
  }
  if (total_vertices > std::numeric_limits<std::uint32_t>::max())
    fail(path, "more than 2^32 vertices (" + std::to_string(total_vertices) + ")");
  mesh.vertices.reserve(total_vertices);
  if (all_normals) mesh.normals.reserve(total_vertices);
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* am = scene.mMeshes[m];
    if (!am || !am->mVertices) continue;
    const std::uint32_t base = std::uint32_t(mesh.vertices.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        fail(path, "vertex " + std::to_string(base + v) + " has a non-finite coordinate");
      mesh.vertices.emplace_back(p.x, p.y, p.z);
      if (all_normals) mesh.normals.emplace_back(am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z);
    }
    // Points and lines in the file are not triangles: they are skipped.
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      TriMesh::Triangle t;
      for (int c = 0; c < 3; ++c) {
        if (face.mIndices[c] >= am->mNumVertices)
          fail(path, "face " + std::to_string(mesh.triangles.size()) + " has vertex index " +
                         std::to_string(face.mIndices[c]) + " out of range (" + std::to_string(am->mNumVertices) +
                         " vertices)");
        t[c] = base + face.mIndices[c];
      }
      mesh.triangles.push_back(t);
    }
  }
  if (mesh.triangles.empty()) fail(path, "no triangles");
  return mesh;
}

}  // namespace

namespace {

// A mesh from the bytes of a file named `path` (its extension picks the format,
// and it names the file in errors); from_disk: side files (OBJ materials, glTF
// buffers) resolve next to it, otherwise the bytes are parsed in memory.
TriMesh mesh_from_bytes(const fs::path& path, std::vector<std::uint8_t> bytes, bool from_disk) {
  std::string ext = detail::extension(path);
  const bool gz = detail::is_gzip_name(path, &ext);
  if (!supported(ext))
    fail(path, "unsupported mesh format '" + ext + "' (expected .ply, .obj, .stl, .off, .gltf or .glb, optionally .gz)");
  if (bytes.empty()) fail(path, "empty file");
  if (gz) bytes = detail::gunzip(path, bytes, max_inflated_mesh);
  if (bytes.empty()) fail(path, "empty file");
  if (ext == ".ply") return mesh_from_ply(path, bytes);
  if (ext == ".off") return mesh_from_off(path, detail::as_text(bytes));
  if (ext == ".stl") return mesh_from_stl(path, bytes);
  pre_validate(path, ext, bytes);

  constexpr unsigned flags = aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                             aiProcess_PreTransformVertices;
  Assimp::Importer importer;
  importer.SetIOHandler(new RegularFilesOnly);  // the importer takes ownership
  const aiScene* scene = nullptr;
  try {
    // In memory for .gz; otherwise from the path so that side files resolve next to it.
    scene = gz || !from_disk ? importer.ReadFileFromMemory(bytes.data(), bytes.size(), flags, ext.c_str() + 1)
                             : importer.ReadFile(path.string(), flags);
  } catch (const std::exception& e) {
    fail(path, std::string("cannot read mesh: ") + e.what());
  }
  if (!scene) fail(path, std::string("cannot read mesh: ") + importer.GetErrorString());
  if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) fail(path, "cannot read mesh: incomplete scene");
  return convert(path, *scene);
}

}  // namespace

TriMesh read_mesh(const fs::path& path) {
  std::string ext = detail::extension(path);
  detail::is_gzip_name(path, &ext);
  if (!supported(ext))
    fail(path, "unsupported mesh format '" + ext + "' (expected .ply, .obj, .stl, .off, .gltf or .glb, optionally .gz)");
  // Standard input ("-") has no folder for side files: parsed in memory.
  return mesh_from_bytes(path, detail::read_file(path), !detail::is_standard_stream(path));
}

TriMesh read_mesh_from_memory(std::span<const std::uint8_t> bytes, const fs::path& name) {
  return mesh_from_bytes(name, std::vector<std::uint8_t>(bytes.begin(), bytes.end()), false);
}

bool is_mesh_name(const fs::path& path) {
  std::string ext = detail::extension(path);
  detail::is_gzip_name(path, &ext);
  return supported(ext);
}

}  // namespace geods::io
