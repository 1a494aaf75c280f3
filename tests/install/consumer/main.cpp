// Uses the installed geods: a predicate, a Morton code and a mesh check.
#include <geods/core/morton.hpp>
#include <geods/core/predicates.hpp>
#include <geods/core/tri_mesh.hpp>

#include <cstdio>

int main() {
  const double a[2] = {0, 0}, b[2] = {1, 0}, c[2] = {0, 1};
  geods::TriMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}};
  const bool ok = geods::orient2d(a, b, c) > 0 && geods::morton2d_encode32(1, 1) == 3 &&
                  mesh.validate().boundary_edges == 3;
  std::printf("consumer: %s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
