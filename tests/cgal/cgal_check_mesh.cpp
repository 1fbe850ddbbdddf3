// cgal_check_mesh FILE: CGAL's verdict on a mesh file as a closed,
// manifold solid without self-intersections (cgal_validity.h), for tool
// tests of what `ldc` writes. Exit 0 and "valid" when it is, 1 and what fails
// otherwise, 2 when the file cannot be read. The file is read by ldc::meshio
// (OBJ, PLY, STL, glTF) with its indices as written: nothing welded.
#include <cstdio>

#include "cgal/cgal_validity.h"
#include "meshio/meshio.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s MESH\n", argv[0]);
    return 2;
  }
  ldc::Result<ldc::TriangleMesh> mesh = ldc::load_mesh(argv[1]);
  if (!mesh.ok()) {
    std::fprintf(stderr, "cgal_check_mesh: %s\n", mesh.status().message().c_str());
    return 2;
  }
  const ldc::cgal_validity::Verdict v = ldc::cgal_validity::check(mesh.value());
  std::printf("%s: %zu triangles, %s\n", argv[1], mesh.value().triangles.size(),
              v.ok() ? "valid" : v.text().c_str());
  return v.ok() ? 0 : 1;
}
