// CGAL's verdict on a mesh as a solid, for the output-validity tests: the
// triangles added to one CGAL::Surface_mesh by their indices (a face CGAL's
// half-edge structure refuses means a non-manifold edge or vertex), then
// is_valid_polygon_mesh, is_closed and Polygon_mesh_processing::
// does_self_intersect (degenerate triangles count as intersections there).
#pragma once

#include <string>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include "ldc/mesh.h"

namespace ldc::cgal_validity {

struct Verdict {
  bool all_faces_added = false;  // every triangle went into one Surface_mesh
  bool valid = false;            // CGAL::is_valid_polygon_mesh
  bool closed = false;           // CGAL::is_closed
  bool self_intersects = true;   // PMP::does_self_intersect
  bool ok() const { return all_faces_added && valid && closed && !self_intersects; }
  std::string text() const {
    return std::string(all_faces_added ? "" : "faces refused (non-manifold); ") + (valid ? "" : "not valid; ") +
           (closed ? "" : "not closed; ") + (self_intersects ? "self-intersecting" : "");
  }
};

template <class Positions, class Triangles>
Verdict check(const Positions& positions, const Triangles& triangles) {
  using Point = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
  using Mesh = CGAL::Surface_mesh<Point>;
  Mesh m;
  std::vector<Mesh::Vertex_index> v;
  v.reserve(positions.size());
  for (const auto& p : positions) v.push_back(m.add_vertex(Point(p.x, p.y, p.z)));
  Verdict out;
  out.all_faces_added = true;
  for (const auto& t : triangles)
    if (m.add_face(v[t[0]], v[t[1]], v[t[2]]) == Mesh::null_face()) out.all_faces_added = false;
  if (!out.all_faces_added) return out;
  out.valid = CGAL::is_valid_polygon_mesh(m);
  out.closed = CGAL::is_closed(m);
  out.self_intersects = CGAL::Polygon_mesh_processing::does_self_intersect(m);
  return out;
}

inline Verdict check(const TriangleMesh& mesh) { return check(mesh.positions, mesh.triangles); }

}  // namespace ldc::cgal_validity
