#include "geods/core/tri_mesh.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/triangle.hpp"

namespace geods {

namespace {

constexpr std::size_t kMaxExamples = 16;

void note(MeshReport& report, std::string text) {
  if (report.examples.size() < kMaxExamples) report.examples.push_back(std::move(text));
}

// A directed edge (from, to) of face `face`, for sorting by undirected key.
struct HalfEdge {
  std::uint32_t lo, hi;  // undirected key
  bool forward;          // from == lo
  std::uint32_t face;
};

}  // namespace

std::vector<std::string> MeshReport::problems() const {
  std::vector<std::string> out;
  auto add = [&](std::size_t n, const char* what) {
    if (n) out.push_back(std::to_string(n) + " " + what);
  };
  add(out_of_range_indices, "out-of-range vertex indices");
  add(non_finite_vertices, "vertices with NaN or infinite coordinates");
  add(degenerate_faces, "degenerate faces");
  add(duplicate_faces, "duplicate faces");
  add(non_manifold_edges, "non-manifold edges");
  add(boundary_edges, "open boundary edges");
  add(inconsistent_edges, "edges with inconsistent face orientation");
  return out;
}

AABB3f TriMesh::bounds() const {
  AABB3f box;
  for (const Vec3f& v : vertices) box.extend(v);
  return box;
}

MeshReport TriMesh::validate() const {
  MeshReport report;
  const std::size_t nv = vertices.size();

  for (std::size_t i = 0; i < nv; ++i) {
    if (!vertices[i].allFinite()) {
      ++report.non_finite_vertices;
      note(report, "vertex " + std::to_string(i) + ": non-finite coordinate");
    }
  }

  std::vector<std::array<std::uint32_t, 3>> sorted_faces;
  std::vector<HalfEdge> edges;
  sorted_faces.reserve(triangles.size());
  edges.reserve(3 * triangles.size());
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    const Triangle& t = triangles[f];
    bool in_range = true;
    for (int c = 0; c < 3; ++c) {
      if (t[c] >= nv) {
        ++report.out_of_range_indices;
        note(report, "face " + std::to_string(f) + ": corner " + std::to_string(t[c]) + " out of range");
        in_range = false;
      }
    }
    if (!in_range) continue;
    const bool repeated = t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
    const Vec3f& a = vertices[t[0]];
    const Vec3f& b = vertices[t[1]];
    const Vec3f& c = vertices[t[2]];
    const bool zero_area = !repeated && has_zero_area(a, b, c);  // exactly: tiny valid triangles are not
    if (repeated || zero_area) {
      ++report.degenerate_faces;
      note(report, "face " + std::to_string(f) + ": degenerate");
    }
    if (repeated) continue;  // its edges would only confuse the edge counts
    std::array<std::uint32_t, 3> key = t;
    std::sort(key.begin(), key.end());
    sorted_faces.push_back(key);
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t from = t[c], to = t[(c + 1) % 3];
      edges.push_back({std::min(from, to), std::max(from, to), from < to, std::uint32_t(f)});
    }
  }

  std::sort(sorted_faces.begin(), sorted_faces.end());
  for (std::size_t i = 1; i < sorted_faces.size(); ++i) {
    if (sorted_faces[i] == sorted_faces[i - 1]) ++report.duplicate_faces;
  }
  if (report.duplicate_faces) note(report, std::to_string(report.duplicate_faces) + " duplicate faces");

  std::sort(edges.begin(), edges.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.lo != y.lo ? x.lo < y.lo : x.hi < y.hi;
  });
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) ++j;
    const std::size_t uses = j - i;
    const std::string name = "edge (" + std::to_string(edges[i].lo) + ", " + std::to_string(edges[i].hi) + ")";
    if (uses == 1) {
      ++report.boundary_edges;
    } else if (uses > 2) {
      ++report.non_manifold_edges;
      note(report, name + ": shared by " + std::to_string(uses) + " faces");
    } else if (edges[i].forward == edges[i + 1].forward) {
      ++report.inconsistent_edges;
      note(report, name + ": faces " + std::to_string(edges[i].face) + " and " +
                       std::to_string(edges[i + 1].face) + " disagree in orientation");
    }
    i = j;
  }
  return report;
}

void TriMesh::require_valid(const std::string& what) const {
  // validate() also sorts the faces and edges (O(n log n)); valid() needs only
  // the coordinates and the indices, so check those first and let validate() word the error.
  std::atomic<bool> bad{false};
  parallel_for(0, vertices.size(), 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e && !bad; ++i)
      if (!vertices[i].allFinite()) bad = true;
  });
  parallel_for(0, triangles.size(), 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e && !bad; ++i)
      for (const std::uint32_t v : triangles[i])
        if (v >= vertices.size()) bad = true;
  });
  if (!bad) return;
  const MeshReport report = validate();
  std::string message = what + ": invalid mesh";
  for (const std::string& p : report.problems()) message += "; " + p;
  if (!report.examples.empty()) message += " (first: " + report.examples.front() + ")";
  throw Error(message);
}

double TriMesh::signed_volume() const {
  double volume = 0;
  for (const Triangle& t : triangles) {
    const Vec3d a = vertices[t[0]].cast<double>();
    const Vec3d b = vertices[t[1]].cast<double>();
    const Vec3d c = vertices[t[2]].cast<double>();
    volume += a.dot(b.cross(c));
  }
  return volume / 6.0;
}

double TriMesh::surface_area() const {
  double area = 0;
  for (const Triangle& t : triangles) {
    area += triangle_area<double>(vertices[t[0]].cast<double>(), vertices[t[1]].cast<double>(),
                                  vertices[t[2]].cast<double>());
  }
  return area;
}

}  // namespace geods
