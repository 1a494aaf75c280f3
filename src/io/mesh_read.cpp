#include <assimp/DefaultIOSystem.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cmath>
#include <limits>

#include "file_util.hpp"
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

// Pre-validation: the cheap checks on counts that a header declares, so that
// Assimp never sees a small file claiming billions of elements.
void check_off(const fs::path& path, std::string_view text) {
  detail::LineReader lines(text);
  std::string_view line;
  std::vector<std::string_view> tokens;
  while (tokens.size() < 3 && lines.next(line)) {
    const std::size_t hash = line.find('#');
    for (std::string_view t : detail::split_fields(line.substr(0, hash))) tokens.push_back(t);
  }
  if (tokens.empty() || tokens[0].size() < 3 || tokens[0].substr(tokens[0].size() - 3) != "OFF")
    fail(path, "not an OFF file (wrong magic)");
  tokens.erase(tokens.begin());
  while (tokens.size() < 2 && lines.next(line))
    for (std::string_view t : detail::split_fields(line.substr(0, line.find('#')))) tokens.push_back(t);
  std::size_t nv = 0, nf = 0;
  if (tokens.size() < 2 || !detail::parse_size(tokens[0], nv) || !detail::parse_size(tokens[1], nf))
    fail(path, "malformed OFF counts line");
  if (nf == 0) fail(path, "no triangles (OFF header declares 0 faces)");
  // Each number takes a digit and a separator: 3 per vertex, at least 4 per face.
  const std::size_t rest = text.size() - std::min(text.size(), lines.offset());
  if (nv > rest / 6 || nf > rest / 8 || nv * 6 + nf * 8 > rest + 1)
    fail(path, "truncated: header declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                   " faces but only " + std::to_string(rest) + " bytes follow");
}

void check_stl(const fs::path& path, std::span<const std::uint8_t> bytes) {
  if (bytes.size() >= 84) {
    const std::uint64_t n = detail::load<std::uint32_t>(bytes.data() + 80, false);
    if (84 + 50 * n == bytes.size()) {
      if (n == 0) fail(path, "no triangles (binary STL with 0 facets)");
      return;
    }
  }
  const std::string_view text = detail::trim(detail::as_text(bytes.first(std::min<std::size_t>(bytes.size(), 512))));
  if (text.substr(0, 5) == "solid") return;
  if (bytes.size() >= 84)
    fail(path, "truncated binary STL: header declares " +
                   std::to_string(detail::load<std::uint32_t>(bytes.data() + 80, false)) + " facets (" +
                   std::to_string(84 + 50 * std::uint64_t(detail::load<std::uint32_t>(bytes.data() + 80, false))) +
                   " bytes), file has " + std::to_string(bytes.size()));
  fail(path, "not an STL file (too short for binary, no 'solid' for ascii)");
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
  if (ext == ".ply") detail::parse_ply_header(path, bytes);
  else if (ext == ".off") check_off(path, detail::as_text(bytes));
  else if (ext == ".stl") check_stl(path, bytes);
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

TriMesh read_mesh(const fs::path& path) {
  std::string ext = detail::extension(path);
  const bool gz = detail::is_gzip_name(path, &ext);
  if (!supported(ext))
    fail(path, "unsupported mesh format '" + ext + "' (expected .ply, .obj, .stl, .off, .gltf or .glb, optionally .gz)");
  std::vector<std::uint8_t> bytes = detail::read_file(path);
  if (bytes.empty()) fail(path, "empty file");
  if (gz) bytes = detail::gunzip(path, bytes, max_inflated_mesh);
  pre_validate(path, ext, bytes);

  constexpr unsigned flags = aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                             aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices;
  Assimp::Importer importer;
  importer.SetIOHandler(new RegularFilesOnly);  // the importer takes ownership
  const aiScene* scene = nullptr;
  try {
    // In memory for .gz; otherwise from the path so that side files resolve next to it.
    scene = gz ? importer.ReadFileFromMemory(bytes.data(), bytes.size(), flags, ext.c_str() + 1)
               : importer.ReadFile(path.string(), flags);
  } catch (const std::exception& e) {
    fail(path, std::string("cannot read mesh: ") + e.what());
  }
  if (!scene) fail(path, std::string("cannot read mesh: ") + importer.GetErrorString());
  if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) fail(path, "cannot read mesh: incomplete scene");
  return convert(path, *scene);
}

}  // namespace geods::io
