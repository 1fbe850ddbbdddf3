// ldc meshes as CGAL Surface_meshes (Epick), for the cgal-labelled tests.
#pragma once

#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include "ldc/mesh.h"

namespace ldc::test {

using CgalKernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalMesh = CGAL::Surface_mesh<CgalKernel::Point_3>;

// Vertices and triangles in ldc's order (vertex i is CGAL's vertex i).
inline CgalMesh to_cgal(const TriangleMesh& m) {
  CgalMesh out;
  std::vector<CgalMesh::Vertex_index> v;
  v.reserve(m.positions.size());
  for (const auto& p : m.positions) v.push_back(out.add_vertex(CgalKernel::Point_3(p.x, p.y, p.z)));
  for (const auto& t : m.triangles) out.add_face(v[t[0]], v[t[1]], v[t[2]]);
  return out;
}

}  // namespace ldc::test
