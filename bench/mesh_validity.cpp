// CGAL's view of a mesh file as a solid (see mesh_validity.h).
#include "mesh_validity.h"

#include <algorithm>
#include <array>
#include <exception>
#include <set>
#include <utility>
#include <vector>

#include <CGAL/box_intersection_d.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

namespace ldc::bench {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

struct SoupVisitor : public PMP::Default_orientation_visitor {
  std::set<std::pair<size_t, size_t>>* edges = nullptr;
  std::set<size_t>* vertices = nullptr;
  void non_manifold_edge(size_t a, size_t b, size_t) { edges->insert({std::min(a, b), std::max(a, b)}); }
  void non_manifold_vertex(size_t v, size_t) { vertices->insert(v); }
};

// Whether triangles t and u intersect beyond what they share, as
// self_intersections decides it for a pair of faces of one mesh.
bool pair_intersects(const std::vector<Point>& p, const glm::uvec3& t, const glm::uvec3& u) {
  int shared = 0;
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) shared += t[k] == u[l] ? 1 : 0;
  if (shared == 0) return CGAL::do_intersect(Triangle(p[t[0]], p[t[1]], p[t[2]]), Triangle(p[u[0]], p[u[1]], p[u[2]]));
  if (shared >= 3) return true;  // the same three vertices twice
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
  m.add_face(t0, t1, t2);
  // A shared edge run the same way is an orientation fault, not an intersection.
  if (m.add_face(u0, u1, u2) == Mesh::null_face()) m.add_face(u0, u2, u1);
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> out;
  PMP::self_intersections(m, std::back_inserter(out));
  return !out.empty();
}

size_t count_pairs_pairwise(const std::vector<Point>& p, const std::vector<glm::uvec3>& tris,
                            const std::vector<char>& degenerate) {
  using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, size_t, CGAL::Box_intersection_d::ID_FROM_BOX_ADDRESS>;
  std::vector<Box> boxes;
  for (size_t f = 0; f < tris.size(); ++f)
    if (!degenerate[f]) boxes.emplace_back(p[tris[f][0]].bbox() + p[tris[f][1]].bbox() + p[tris[f][2]].bbox(), f);
  std::vector<const Box*> ptr;
  for (const Box& b : boxes) ptr.push_back(&b);
  size_t pairs = 0;
  CGAL::box_self_intersection_d<CGAL::Sequential_tag>(
      ptr.begin(), ptr.end(),
      [&](const Box* a, const Box* b) { pairs += pair_intersects(p, tris[a->info()], tris[b->info()]) ? 1 : 0; },
      std::ptrdiff_t(2000));
  return pairs;
}

}  // namespace

MeshValidity check_mesh_file(const std::string& path) {
  MeshValidity r;
  std::vector<Point> points;
  std::vector<std::vector<size_t>> polygons;
  try {
    r.read = CGAL::IO::read_polygon_soup(path, points, polygons);
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  if (!r.read || polygons.empty()) {
    r.read = false;
    if (r.error.empty()) r.error = "CGAL::IO::read_polygon_soup failed or found no polygons";
    return r;
  }
  r.vertices = points.size();
  for (const auto& poly : polygons) {
    for (size_t k = 1; k + 1 < poly.size(); ++k)
      r.mesh.triangles.push_back({uint32_t(poly[0]), uint32_t(poly[k]), uint32_t(poly[k + 1])});
  }
  r.triangles = r.mesh.triangles.size();
  r.mesh.positions.reserve(points.size());
  for (const Point& q : points) r.mesh.positions.push_back({q.x(), q.y(), q.z()});

  // Non-manifold simplices of the soup as written (orient_polygon_soup reports them to its visitor).
  std::vector<Point> oriented_points = points;
  std::vector<std::vector<size_t>> oriented = polygons;
  std::set<std::pair<size_t, size_t>> edges;
  std::set<size_t> vertices;
  SoupVisitor visitor;
  visitor.edges = &edges;
  visitor.vertices = &vertices;
  r.polygon_mesh = PMP::is_polygon_soup_a_polygon_mesh(polygons);
  PMP::orient_polygon_soup(oriented_points, oriented, CGAL::parameters::visitor(visitor));
  r.nonmanifold_edges = edges.size();
  r.nonmanifold_vertices = vertices.size();

  Mesh mesh;
  if (r.polygon_mesh) {
    PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
    r.valid = CGAL::is_valid_polygon_mesh(mesh);
  } else if (PMP::is_polygon_soup_a_polygon_mesh(oriented)) {
    PMP::polygon_soup_to_polygon_mesh(oriented_points, oriented, mesh);
  }
  if (!mesh.is_empty()) {
    r.closed = CGAL::is_closed(mesh);
    std::vector<Mesh::Halfedge_index> cycles;
    PMP::extract_boundary_cycles(mesh, std::back_inserter(cycles));
    r.border_cycles = cycles.size();
  }

  // Self-intersections.
  const std::vector<glm::uvec3>& tris = r.mesh.triangles;
  std::vector<char> degenerate(tris.size(), 0);
  for (size_t f = 0; f < tris.size(); ++f)
    if (CGAL::collinear(points[tris[f][0]], points[tris[f][1]], points[tris[f][2]])) degenerate[f] = 1, ++r.degenerate;
  Mesh whole;
  for (const Point& q : points) whole.add_vertex(q);
  bool all_added = true;
  for (size_t f = 0; f < tris.size() && all_added; ++f)
    all_added = whole.add_face(Mesh::Vertex_index(tris[f][0]), Mesh::Vertex_index(tris[f][1]),
                               Mesh::Vertex_index(tris[f][2])) != Mesh::null_face();
  if (all_added) {
    std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> out;
    PMP::self_intersections<CGAL::Parallel_if_available_tag>(whole, std::back_inserter(out));
    for (const auto& [f, g] : out) r.self_intersections += f != g ? 1 : 0;
  } else {
    r.pairwise = true;
    r.self_intersections = count_pairs_pairwise(points, tris, degenerate);
  }
  return r;
}

}  // namespace ldc::bench
