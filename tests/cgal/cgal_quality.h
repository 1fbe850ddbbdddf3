// CGAL's counts of what mesh_quality counts, for tests/cgal/test_cgal_reference.cpp:
// self-intersecting triangle pairs (Polygon_mesh_processing::self_intersections)
// and non-manifold edges and vertices (orient_polygon_soup's visitor).
//
// A contoured mesh can have non-manifold edges, which a CGAL::Surface_mesh
// cannot hold (add_face refuses the third face on an edge). So the pairs are
// counted the way self_intersections counts them, pair by pair, on meshes
// that hold just the pair: CGAL's box_self_intersection_d over the triangles'
// boxes (closed, as self_intersections uses), then for each pair of boxes
// - no shared vertex: CGAL::do_intersect of the two triangles (what
//   self_intersections does for such a pair);
// - a shared vertex or edge: self_intersections on a Surface_mesh of the two
//   triangles, welded by index (the second reversed when it runs the shared
//   edge the same way, which CGAL's test does not look at);
// - the same three vertices: counted (they cannot be two faces of a mesh).
// Triangles with collinear corners are left out, as self_intersections leaves
// them out (it reports each as the pair (f, f)). Where every triangle can be
// added to one Surface_mesh, self_intersections is also run on the whole mesh.
#pragma once

#include <array>
#include <cstdio>
#include <optional>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include <CGAL/box_intersection_d.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include "contour/contour.h"

namespace ldc::cgal_quality {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

struct Counts {
  size_t pairs = 0;                       // pair by pair
  std::optional<size_t> whole_mesh_pairs;  // self_intersections on the whole mesh, where it is a Surface_mesh
  size_t degenerate = 0;                  // collinear triangles (not tested)
  size_t nonmanifold_edges = 0;
  size_t nonmanifold_vertices = 0;
};

inline std::vector<Point> points(const ContourMesh& m) {
  std::vector<Point> p;
  p.reserve(m.vertex_count());
  for (const glm::dvec3& q : m.positions) p.emplace_back(q.x, q.y, q.z);
  return p;
}

// Whether triangles t and u intersect beyond what they share, by CGAL.
inline bool pair_intersects(const std::vector<Point>& p, const glm::uvec3& t, const glm::uvec3& u) {
  int shared = 0;
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) shared += t[k] == u[l] ? 1 : 0;
  if (shared == 0) return CGAL::do_intersect(Triangle(p[t[0]], p[t[1]], p[t[2]]), Triangle(p[u[0]], p[u[1]], p[u[2]]));
  if (shared >= 3) return true;
  Mesh m;
  std::vector<std::pair<uint32_t, Mesh::Vertex_index>> ids;
  auto vertex = [&](uint32_t i) {
    for (const auto& [index, v] : ids)
      if (index == i) return v;
    ids.emplace_back(i, m.add_vertex(p[i]));
    return ids.back().second;
  };
  const Mesh::Vertex_index t0 = vertex(t[0]), t1 = vertex(t[1]), t2 = vertex(t[2]);
  const Mesh::Vertex_index u0 = vertex(u[0]), u1 = vertex(u[1]), u2 = vertex(u[2]);
  if (m.add_face(t0, t1, t2) == Mesh::null_face()) throw std::runtime_error("CGAL refused a triangle");
  if (m.add_face(u0, u1, u2) == Mesh::null_face() && m.add_face(u0, u2, u1) == Mesh::null_face())
    throw std::runtime_error("CGAL refused a triangle pair");
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> out;
  PMP::self_intersections(m, std::back_inserter(out));
  return !out.empty();
}

// Non-manifold edges (each once) and vertices as orient_polygon_soup reports them.
struct SoupVisitor : public PMP::Default_orientation_visitor {
  std::set<std::pair<size_t, size_t>>* edges = nullptr;
  std::set<size_t>* vertices = nullptr;
  void non_manifold_edge(size_t a, size_t b, size_t) { edges->insert({std::min(a, b), std::max(a, b)}); }
  void non_manifold_vertex(size_t v, size_t) { vertices->insert(v); }
};

inline Counts counts(const ContourMesh& m) {
  Counts c;
  const std::vector<Point> p = points(m);

  // Pairs, with boxes as self_intersections makes them.
  using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, size_t, CGAL::Box_intersection_d::ID_FROM_BOX_ADDRESS>;
  std::vector<Box> boxes;
  for (size_t f = 0; f < m.triangle_count(); ++f) {
    const glm::uvec3& t = m.triangles[f];
    if (CGAL::collinear(p[t[0]], p[t[1]], p[t[2]])) {
      ++c.degenerate;
      continue;
    }
    boxes.emplace_back(p[t[0]].bbox() + p[t[1]].bbox() + p[t[2]].bbox(), f);
  }
  std::vector<const Box*> box_ptr;
  for (const Box& b : boxes) box_ptr.push_back(&b);
  CGAL::box_self_intersection_d<CGAL::Sequential_tag>(
      box_ptr.begin(), box_ptr.end(),
      [&](const Box* a, const Box* b) {
        if (pair_intersects(p, m.triangles[a->info()], m.triangles[b->info()])) ++c.pairs;
      },
      std::ptrdiff_t(2000));

  // The whole mesh, where CGAL can hold it.
  Mesh whole;
  for (const Point& q : p) whole.add_vertex(q);
  bool all_added = true;
  for (const glm::uvec3& t : m.triangles) {
    if (whole.add_face(Mesh::Vertex_index(t[0]), Mesh::Vertex_index(t[1]), Mesh::Vertex_index(t[2])) ==
        Mesh::null_face()) {
      all_added = false;
      break;
    }
  }
  if (all_added) {
    std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> out;
    PMP::self_intersections(whole, std::back_inserter(out));
    size_t pairs = 0;
    for (const auto& [f, g] : out) pairs += f != g ? 1 : 0;
    c.whole_mesh_pairs = pairs;
  }

  // Non-manifold simplices.
  std::vector<Point> soup_points = p;
  std::vector<std::vector<size_t>> polygons;
  for (const glm::uvec3& t : m.triangles) polygons.push_back({t[0], t[1], t[2]});
  std::set<std::pair<size_t, size_t>> edges;
  std::set<size_t> vertices;
  SoupVisitor visitor;
  visitor.edges = &edges;
  visitor.vertices = &vertices;
  PMP::orient_polygon_soup(soup_points, polygons, CGAL::parameters::visitor(visitor));
  c.nonmanifold_edges = edges.size();
  c.nonmanifold_vertices = vertices.size();
  return c;
}

}  // namespace ldc::cgal_quality
