// CGAL pieces of the benchmarks: the stanford bunny with its holes closed by
// CGAL's triangulate_hole (the closed reference the peers are measured on,
// PEERS.md "bunny_sphere"), and self-intersection counts.
#include <map>
#include <set>
#include <tuple>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>

#include "bench_common.h"

namespace ldc::bench {

TriangleMesh fill_holes(const TriangleMesh& m, size_t* holes) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
  Mesh cm;
  std::vector<Mesh::Vertex_index> v;
  for (const auto& p : m.positions) v.push_back(cm.add_vertex(Kernel::Point_3(p.x, p.y, p.z)));
  for (const auto& t : m.triangles) cm.add_face(v[t[0]], v[t[1]], v[t[2]]);
  std::set<Mesh::Halfedge_index> seen;
  size_t filled = 0;
  for (auto h : halfedges(cm)) {
    if (!cm.is_border(h) || seen.count(h)) continue;
    for (auto g : CGAL::halfedges_around_face(h, cm)) seen.insert(g);
    std::vector<Mesh::Face_index> added;
    CGAL::Polygon_mesh_processing::triangulate_hole(cm, h, std::back_inserter(added));
    ++filled;
  }
  if (holes) *holes = filled;
  TriangleMesh out;
  std::vector<uint32_t> index(cm.number_of_vertices() + cm.number_of_removed_vertices(), 0);
  for (auto vi : cm.vertices()) {
    index[vi] = uint32_t(out.positions.size());
    const auto& p = cm.point(vi);
    out.positions.push_back({p.x(), p.y(), p.z()});
  }
  for (auto f : cm.faces()) {
    glm::uvec3 t;
    int i = 0;
    for (auto vi : CGAL::vertices_around_face(cm.halfedge(f), cm)) t[i++] = index[vi];
    out.triangles.push_back(t);
  }
  return out;
}

size_t self_intersections(const TriangleMesh& m) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
  Mesh cm;
  // Weld equal positions first: meshes written chunk by chunk (marching cubes
  // here) repeat border vertices, which would count as touching triangles.
  std::map<std::tuple<double, double, double>, Mesh::Vertex_index> welded;
  std::vector<Mesh::Vertex_index> v;
  for (const auto& p : m.positions) {
    auto [it, fresh] = welded.try_emplace({p.x, p.y, p.z}, Mesh::null_vertex());
    if (fresh) it->second = cm.add_vertex(Kernel::Point_3(p.x, p.y, p.z));
    v.push_back(it->second);
  }
  for (const auto& t : m.triangles) {
    if (cm.add_face(v[t[0]], v[t[1]], v[t[2]]) == Mesh::null_face()) {
      // A face a half-edge structure refuses (non-manifold): give it its own corners.
      cm.add_face(cm.add_vertex(cm.point(v[t[0]])), cm.add_vertex(cm.point(v[t[1]])), cm.add_vertex(cm.point(v[t[2]])));
    }
  }
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(cm, std::back_inserter(pairs));
  return pairs.size();
}

}  // namespace ldc::bench
