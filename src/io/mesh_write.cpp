#include <fmt/format.h>

#include <cstring>

#include "file_util.hpp"
#include "geods/io/mesh_io.hpp"

namespace geods::io {

namespace fs = std::filesystem;
using detail::fail;

namespace {

// Appends the little-endian bytes of v.
template <typename T>
void put(std::vector<std::uint8_t>& out, T v) {
  std::uint8_t b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(b, b + sizeof(T));
  out.insert(out.end(), b, b + sizeof(T));
}

// Everything write_mesh refuses is found here, before a byte is written: the
// files it writes are files read_mesh reads back.
void check_writable(const fs::path& path, const TriMesh& mesh) {
  const std::size_t n = mesh.vertices.size();
  for (std::size_t v = 0; v < n; ++v)
    if (!mesh.vertices[v].allFinite())
      fail(path, fmt::format("cannot write mesh: vertex {} has a non-finite coordinate ({:g}, {:g}, {:g})", v,
                             mesh.vertices[v].x(), mesh.vertices[v].y(), mesh.vertices[v].z()));
  for (std::size_t v = 0; v < mesh.normals.size(); ++v)
    if (!mesh.normals[v].allFinite()) fail(path, fmt::format("cannot write mesh: normal {} is not finite", v));
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    for (std::uint32_t i : mesh.triangles[f])
      if (i >= n)
        fail(path, "cannot write mesh: face " + std::to_string(f) + " has vertex index " + std::to_string(i) +
                       " out of range (" + std::to_string(n) + " vertices)");
  if (!mesh.normals.empty() && mesh.normals.size() != n)
    fail(path, "cannot write mesh: " + std::to_string(mesh.normals.size()) + " normals for " + std::to_string(n) +
                   " vertices");
}

void write_ply(const fs::path& path, const TriMesh& mesh, MeshEncoding encoding) {
  const bool normals = !mesh.normals.empty();
  std::string header = fmt::format("ply\nformat {} 1.0\ncomment written by geods\nelement vertex {}\n",
                                   encoding == MeshEncoding::binary ? "binary_little_endian" : "ascii",
                                   mesh.vertices.size());
  header += "property float x\nproperty float y\nproperty float z\n";
  if (normals) header += "property float nx\nproperty float ny\nproperty float nz\n";
  header += fmt::format("element face {}\nproperty list uchar int vertex_indices\nend_header\n", mesh.triangles.size());
  if (encoding == MeshEncoding::ascii) {
    fmt::memory_buffer out;
    out.append(header);
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
      const Vec3f& p = mesh.vertices[v];
      // {} is the shortest text that reads back to the same float.
      if (normals) {
        const Vec3f& n = mesh.normals[v];
        fmt::format_to(std::back_inserter(out), "{} {} {} {} {} {}\n", p.x(), p.y(), p.z(), n.x(), n.y(), n.z());
      } else {
        fmt::format_to(std::back_inserter(out), "{} {} {}\n", p.x(), p.y(), p.z());
      }
    }
    for (const auto& t : mesh.triangles) fmt::format_to(std::back_inserter(out), "3 {} {} {}\n", t[0], t[1], t[2]);
    detail::write_file(path, std::string_view(out.data(), out.size()));
    return;
  }
  std::vector<std::uint8_t> out(header.begin(), header.end());
  out.reserve(out.size() + mesh.vertices.size() * (normals ? 24 : 12) + mesh.triangles.size() * 13);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    for (int c = 0; c < 3; ++c) put(out, mesh.vertices[v][c]);
    if (normals)
      for (int c = 0; c < 3; ++c) put(out, mesh.normals[v][c]);
  }
  for (const auto& t : mesh.triangles) {
    out.push_back(3);
    for (std::uint32_t i : t) put(out, std::int32_t(i));
  }
  detail::write_file(path, out);
}

void write_obj(const fs::path& path, const TriMesh& mesh) {
  const bool normals = !mesh.normals.empty();
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out), "# written by geods: {} vertices, {} triangles\n", mesh.vertices.size(),
                 mesh.triangles.size());
  for (const Vec3f& p : mesh.vertices) fmt::format_to(std::back_inserter(out), "v {} {} {}\n", p.x(), p.y(), p.z());
  if (normals)
    for (const Vec3f& n : mesh.normals) fmt::format_to(std::back_inserter(out), "vn {} {} {}\n", n.x(), n.y(), n.z());
  for (const auto& t : mesh.triangles) {
    if (normals)
      fmt::format_to(std::back_inserter(out), "f {0}//{0} {1}//{1} {2}//{2}\n", t[0] + 1ull, t[1] + 1ull, t[2] + 1ull);
    else
      fmt::format_to(std::back_inserter(out), "f {} {} {}\n", t[0] + 1ull, t[1] + 1ull, t[2] + 1ull);
  }
  detail::write_file(path, std::string_view(out.data(), out.size()));
}

Vec3f facet_normal(const TriMesh& mesh, const TriMesh::Triangle& t) {
  const Vec3f& a = mesh.vertices[t[0]];
  const Vec3f n = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);
  const float len = n.norm();
  return len > 0 ? Vec3f(n / len) : Vec3f::Zero();
}

void write_stl(const fs::path& path, const TriMesh& mesh, MeshEncoding encoding) {
  if (encoding == MeshEncoding::ascii) {
    fmt::memory_buffer out;
    fmt::format_to(std::back_inserter(out), "solid geods\n");
    for (const auto& t : mesh.triangles) {
      const Vec3f n = facet_normal(mesh, t);
      fmt::format_to(std::back_inserter(out), "  facet normal {} {} {}\n    outer loop\n", n.x(), n.y(), n.z());
      for (std::uint32_t i : t) {
        const Vec3f& p = mesh.vertices[i];
        fmt::format_to(std::back_inserter(out), "      vertex {} {} {}\n", p.x(), p.y(), p.z());
      }
      fmt::format_to(std::back_inserter(out), "    endloop\n  endfacet\n");
    }
    fmt::format_to(std::back_inserter(out), "endsolid geods\n");
    detail::write_file(path, std::string_view(out.data(), out.size()));
    return;
  }
  if (mesh.triangles.size() > 0xffffffffu) fail(path, "too many triangles for binary STL");
  // The 80-byte header must not start with "solid", or readers take the file for ascii.
  std::vector<std::uint8_t> out(80, ' ');
  const std::string_view tag = "binary STL written by geods";
  std::copy(tag.begin(), tag.end(), out.begin());
  out.reserve(84 + 50 * mesh.triangles.size());
  put(out, std::uint32_t(mesh.triangles.size()));
  for (const auto& t : mesh.triangles) {
    const Vec3f n = facet_normal(mesh, t);
    for (int c = 0; c < 3; ++c) put(out, n[c]);
    for (std::uint32_t i : t)
      for (int c = 0; c < 3; ++c) put(out, mesh.vertices[i][c]);
    put(out, std::uint16_t(0));
  }
  detail::write_file(path, out);
}

}  // namespace

void write_mesh(const fs::path& path, const TriMesh& mesh, MeshEncoding encoding) {
  if (detail::is_standard_stream(path)) fail(path, "meshes are written to files (.ply, .obj or .stl), not to standard output");
  check_writable(path, mesh);
  const std::string ext = detail::extension(path);
  if (ext == ".ply") write_ply(path, mesh, encoding);
  else if (ext == ".obj") write_obj(path, mesh);
  else if (ext == ".stl") write_stl(path, mesh, encoding);
  else fail(path, "unsupported mesh format '" + ext + "' for writing (expected .ply, .obj or .stl)");
}

}  // namespace geods::io
