// Accuracy of stored points against the exact mesh, with CGAL's AABB tree.
// The only translation unit of the benchmarks that includes CGAL.
#include <cmath>
#include <cstdio>
#include <boost/variant/get.hpp>

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/compute_normal.h>
#include <CGAL/Surface_mesh.h>

#include "bench_common.h"
#include "ldc/build.h"

namespace ldc::bench {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

// Triangle soup (no topology needed): every triangle its own face.
Mesh soup(const TriangleMesh& m) {
  Mesh out;
  for (const auto& t : m.triangles) {
    Mesh::Vertex_index v[3];
    for (int i = 0; i < 3; ++i) {
      const glm::dvec3& p = m.positions[t[i]];
      v[i] = out.add_vertex(Point(p.x, p.y, p.z));
    }
    out.add_face(v[0], v[1], v[2]);
  }
  return out;
}

struct Accuracy {
  size_t checked = 0, synthetic = 0;
  double depth_max = 0, depth_sum = 0, normal_max = 0, normal_sum = 0;
  size_t depth_over = 0, normal_over = 0;  // beyond h/1000 and 0.1 degrees
};

void check_point(const Tree& tree, const Mesh& mesh, const glm::dvec3& p, int axis, const glm::vec3& n,
                 double h, Accuracy& acc) {
  glm::dvec3 d(0.0);
  d[axis] = 0.01 * h;
  Kernel::Segment_3 seg(Point(p.x - d.x, p.y - d.y, p.z - d.z), Point(p.x + d.x, p.y + d.y, p.z + d.z));
  std::vector<Tree::Intersection_and_primitive_id<Kernel::Segment_3>::Type> hits;
  tree.all_intersections(seg, std::back_inserter(hits));
  double best = 1e300;
  for (const auto& hit : hits) {
    if (const Point* q = boost::get<Point>(&hit.first)) best = std::min(best, std::abs((*q)[axis] - p[axis]));
  }
  if (best > 1e299) {
    ++acc.synthetic;  // a point the repair added over a hole: no surface there
    return;
  }
  // A ray through a shared edge meets both faces at the same depth: either
  // face's normal is right, so take the closer one.
  double best_cos = -1.0;
  Mesh::Face_index face;
  for (const auto& hit : hits) {
    const Point* q = boost::get<Point>(&hit.first);
    if (!q || std::abs((*q)[axis] - p[axis]) > best + 1e-9 * h) continue;
    auto fn = CGAL::Polygon_mesh_processing::compute_face_normal(hit.second, mesh);
    double c = std::abs(glm::dot(glm::normalize(glm::dvec3(fn.x(), fn.y(), fn.z())), glm::dvec3(n)));
    if (c > best_cos) {
      best_cos = c;
      face = hit.second;
    }
  }
  auto fn = CGAL::Polygon_mesh_processing::compute_face_normal(face, mesh);
  glm::dvec3 f(fn.x(), fn.y(), fn.z());
  double c = std::abs(glm::dot(glm::normalize(f), glm::dvec3(n)));
  double deg = std::acos(std::min(1.0, c)) * 180.0 / M_PI;
  ++acc.checked;
  acc.depth_over += best / h > 1e-3;
  acc.normal_over += deg > 0.1;
  acc.depth_max = std::max(acc.depth_max, best / h);
  acc.depth_sum += best / h;
  acc.normal_max = std::max(acc.normal_max, deg);
  acc.normal_sum += deg;
}

Accuracy measure(const World& w, const TriangleMesh& m) {
  Mesh mesh = soup(m);
  Tree tree(faces(mesh).first, faces(mesh).second, mesh);
  Accuracy acc;
  const int c = w.chunk_size();
  const double h = w.lattice().cell_size;
  w.for_each_chunk([&](const glm::ivec3& ch, ChunkKind, const Chunk* data) {
    if (!data) return;
    for (int a = 0; a < 3; ++a) {
      for (int r = 0; r < c * c; ++r) {
        for (const PackedPoint& pp : data->axis[a].points(r)) {
          SurfacePoint s = decode_point(pp, c, ch[a] * c);
          glm::dvec3 q;
          q[a] = s.depth;
          q[axis_u(a)] = ch[axis_u(a)] * c + r % c;
          q[axis_v(a)] = ch[axis_v(a)] * c + r / c;
          check_point(tree, mesh, w.lattice().to_world(q), a, s.normal, h, acc);
        }
      }
    }
  });
  return acc;
}

}  // namespace

void print_accuracy(const Args& args, const std::vector<int>& resolutions) {
  std::printf("\n### Stored points against the exact mesh (every point; CGAL AABB tree)\n\n");
  std::printf("| mesh | cells | points on the mesh | points over holes (repair) | depth error max (h) "
              "| depth error mean (h) | points > h/1000 | normal error max (deg) | normal error mean (deg) | points > 0.1 deg |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& name : args.meshes) {
    TriangleMesh m = load(args, name);
    for (int cells : resolutions) {
      World w = build_from_mesh(m, {.cells = cells}).value();
      Accuracy a = measure(w, m);
      std::printf("| %s | %d | %zu | %zu | %.2e | %.2e | %zu | %.4f | %.4f | %zu |\n", name.c_str(), cells,
                  a.checked, a.synthetic, a.depth_max, a.depth_sum / std::max<size_t>(a.checked, 1), a.depth_over,
                  a.normal_max, a.normal_sum / std::max<size_t>(a.checked, 1), a.normal_over);
      std::fflush(stdout);
    }
  }
}

}  // namespace ldc::bench
